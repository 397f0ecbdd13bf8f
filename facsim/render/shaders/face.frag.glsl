// Face fragment shader. One variant per region (render.py draws each region's faces with its
// own program, so a fragment runs only its region's code: on llvmpipe both sides of a branch
// cost, even when a uniform switches one off). Variants:
//   REGION_SKIN (+ USE_UV, USE_WRINKLE; + USE_BROWS for triangles under painted brows),
//   REGION_EYEBALL (+ USE_EYE), REGION_TEETH, REGION_TONGUE, REGION_MOUTH_INTERIOR,
//   REGION_LASHES (+ USE_LASH).
// All colour uniforms are linear RGB (render.py linearises the appearance's sRGB colours).

#include "common.glsl"

in vec3 v_pos;
in vec3 v_normal;
in float v_occlusion;
#ifdef USE_UV
in vec2 v_uv;
#endif
#ifdef USE_EYE
in vec3 v_eye;
#endif
#ifdef USE_WRINKLE
in float v_wrinkle;
in float v_crease;
#endif
#ifdef USE_LASH
in float v_lash;
#endif

out vec4 f_color;

// Two-sided, winding-agnostic: the normal was computed from the same winding that decides
// gl_FrontFacing, so flipping on back faces always yields the side facing the viewer.
vec3 surface_normal() {
    vec3 n = normalize(v_normal);
    return gl_FrontFacing ? n : -n;
}

// Diffuse + ambient from the whole rig. `wrap` > 0 lets light bleed past the terminator per
// channel (a cheap subsurface look when red wraps furthest). `occ` (ambient visibility)
// dims the ambient, fill and rim fully and the key partly: there are no cast shadows, so
// occlusion stands in for them in creases and sockets.
const float KEY_OCCLUSION = 0.6;
vec3 diffuse_light(vec3 n, vec3 wrap, float occ) {
    vec3 k = clamp((dot(n, u_key_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    vec3 f = clamp((dot(n, u_fill_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    vec3 r = clamp((dot(n, u_rim_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    return k * u_key_col * mix(1.0, occ, KEY_OCCLUSION)
         + (f * u_fill_col + r * u_rim_col + hemisphere(n)) * occ;
}

vec3 specular_light(vec3 n, vec3 v, float shininess) {
    return blinn(n, u_key_dir, v, shininess) * u_key_col
         + blinn(n, u_fill_dir, v, shininess) * u_fill_col
         + blinn(n, u_rim_dir, v, shininess) * u_rim_col;
}

#ifdef REGION_SKIN
uniform sampler2D u_paint;   // R brow hair density, G lips, B eyelids, A cheek blush
uniform sampler2D u_detail;  // R redness, G beard area, B oiliness, A age lines
uniform float u_beard;       // 0..1 stubble shadow
uniform float u_age;         // 0..1 how much the age lines show
uniform vec3 u_skin;
uniform vec3 u_lips;
uniform vec3 u_brows;
uniform vec3 u_eyelid;
uniform vec3 u_cheek;
uniform float u_wrinkle_darken;

#ifdef USE_WRINKLE
// Creases: thin dark furrows with a faint lit ridge beside each, one at each whole number of
// the crease phase (v_crease, in furrow spacings), slightly wavy, fading in with the wrinkle
// amount and to their mean where they would be finer than a pixel.
float crease_shade(float wrinkle, float phase, vec2 uv) {
    float s = phase + 0.5 * value_noise(uv * vec2(40.0, 25.0), 0);
    float c = cos(2.0 * PI * s);
    float valley = pow(0.5 + 0.5 * c, 10.0);
    float ridge = pow(0.5 + 0.5 * cos(2.0 * PI * (s + 0.22)), 8.0);
    float lines = 1.0 - 0.55 * valley + 0.12 * ridge;
    float detail = clamp(2.0 - 3.0 * fwidth(s), 0.0, 1.0);
    float amount = smoothstep(0.15, 0.9, wrinkle);
    float cavity = 1.0 - u_wrinkle_darken * clamp(wrinkle, 0.0, 1.0);
    return mix(1.0, mix(0.93, lines, detail), amount) * cavity;
}
#endif

// Brow hair: thin strokes whose coverage grows with the painted density. u_brow_frame maps
// skin UV to stroke space (x along the hairs, one unit ~ a stroke length; y across, one unit
// ~ a strand width); render.py's default fits hm08's UV layout. Where strands would be finer
// than a pixel the pattern fades to its mean coverage, so it does not alias.
#ifdef USE_BROWS
uniform mat2 u_brow_frame;
// Returns (coverage, strand shade) for the brow colour over skin.
vec2 brow_hair(vec2 uv, float density) {
    vec2 p = u_brow_frame * uv;
    p.y += 0.6 * sin(p.x * 1.3) + 1.5 * value_noise(p * vec2(0.4, 0.004), 0);
    float n = 0.6 * value_noise(p, 0) + 0.4 * value_noise(p * vec2(2.3, 1.9) + 31.0, 0);
    float aa = fwidth(n) + 0.04;
    // Hairs exist where the noise beats 1 - density (sparse, broken edges); inside, they
    // cover the skin by 55-95 % in streaks.
    float present = smoothstep(1.0 - density - aa, 1.0 - density + aa, n);
    float streaks = smoothstep(0.3 - aa, 0.7 + aa, n);
    float strands = present * (0.55 + 0.4 * streaks);
    float detail = clamp(2.5 - 2.0 * fwidth(p.y), 0.0, 1.0);   // strands per pixel across
    float cover = mix(0.7 * smoothstep(0.0, 0.8, density), strands, detail);
    return vec2(cover, mix(1.0, 0.8 + 0.4 * n, detail));
}
#endif
#endif

#ifdef REGION_EYEBALL
uniform vec3 u_sclera;
uniform vec3 u_iris;
uniform vec3 u_pupil;
// Radii as fractions of the eyeball radius, measured in the plane across the gaze axis
// (length of eye_coord.xy on the front half). hm08's eyeballs are 1.59 cm in radius:
// an iris 11.7 mm across (the adult mean) and a 4 mm pupil.
const float IRIS_RADIUS = 0.368;
const float PUPIL_RADIUS = 0.13;
const float LIMBUS_WIDTH = 0.22;   // fraction of the iris annulus darkened at its rim
const int IRIS_FIBRES = 96;        // radial noise cells around the iris
#endif

#if defined(REGION_TEETH) || defined(REGION_TONGUE)
#define ONE_ALBEDO
#endif
#if defined(ONE_ALBEDO) || defined(REGION_MOUTH_INTERIOR) || defined(REGION_LASHES)
uniform vec3 u_albedo;
#endif

#ifdef REGION_LASHES
// Lashes are drawn last, blended. render.py puts each lash vertex's root-to-tip coordinate
// (0 at the lid, 1 at the tip: distance from the nearest eyeball centre, normalised per lash
// strip) in in_wrinkle's slot. Strands are a stripe pattern along world x (the lid line in
// the head's frame) whose strands end at random lengths, so the lash strips read as tapering
// hairs rather than a dark band.
const float LASH_STRANDS_PER_DM = 300.0;
#endif

void main() {
    vec3 n = surface_normal();
    vec3 v = normalize(u_cam_pos - v_pos);
    float occ = clamp(v_occlusion, 0.0, 1.0);
    float alpha = 1.0;
    vec3 radiance;

#ifdef REGION_SKIN
    vec4 paint = texture(u_paint, v_uv);
    vec4 detail = texture(u_detail, v_uv);
    // Mottling at two scales so large areas are not a flat plastic colour; stronger with age.
    float mottle = 0.6 * value_noise(v_uv * 150.0, 0) + 0.4 * value_noise(v_uv * 600.0 + 17.0, 0);
    vec3 albedo = u_skin * (1.0 + vec3(0.07, 0.09, 0.10) * (1.0 + 1.5 * u_age) * (mottle - 0.5));
    // Regional colour: redder nose, cheeks and ears; a shaved beard's blue-grey shadow.
    albedo *= mix(vec3(1.0), vec3(1.04, 0.80, 0.78), 0.6 * detail.r);
    albedo = mix(albedo, albedo * vec3(0.70, 0.72, 0.78), u_beard * detail.g * (1.0 - paint.g));
    albedo = mix(albedo, u_cheek, paint.a);
    albedo = mix(albedo, u_eyelid, paint.b);
    albedo = mix(albedo, u_lips, paint.g);
#ifdef USE_BROWS
    vec2 brow = brow_hair(v_uv, paint.r);
#else
    vec2 brow = vec2(0.0, 1.0);
#endif
    float hair = brow.x;
    albedo = mix(albedo, u_brows * brow.y, hair);
    float cavity = 1.0 - 0.38 * u_age * detail.a;   // age lines and folds
#ifdef USE_WRINKLE
    cavity *= crease_shade(v_wrinkle, v_crease, v_uv);
#endif
#ifdef USE_PORES
    // Pores and fine relief: a bump from high-frequency noise (surface gradient from screen
    // derivatives), faded out where it would be finer than a pixel, so it never shimmers.
    // Compiled only for large images (render.py), where pores are bigger than a pixel.
    float pore_h = value_noise(v_uv * 2400.0, 0) + 0.5 * value_noise(v_uv * 900.0 + 3.0, 0);
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    vec3 grad = sign(det) * (dFdx(pore_h) * r1 + dFdy(pore_h) * r2);
    float pore_fade = clamp(1.5 - 40.0 * fwidth(v_uv.x * 100.0), 0.0, 1.0);
    vec3 bumped = normalize(abs(det) * n - (0.0006 + 0.0008 * u_age) * pore_fade * grad);
#else
    vec3 bumped = n;
#endif
    // Soft subsurface look: light wraps past the terminator, red furthest (less with age).
    vec3 wrap = vec3(0.5, 0.24, 0.17) * (1.0 - hair) * (1.0 - 0.3 * u_age);
    vec3 diffuse = diffuse_light(n, wrap, occ) * albedo;
    // Sheen: broad and low on skin, glossier on the oily T-zone, tight and strong on the wet
    // lips; none on hair. Pores break up the sheen (bumped normal in the specular only).
    float ndv = max(dot(n, v), 0.0);
    float fres = schlick(0.028, ndv);
    float lips = paint.g;
    float oil = mix(0.55, 1.6, detail.b) * (1.0 - 0.35 * u_age);
    vec3 spec = specular_light(bumped, v, mix(mix(14.0, 28.0, detail.b), 70.0, lips)) * mix(oil, 2.2, lips);
    radiance = (diffuse + spec * fres * (1.0 - hair) * occ) * cavity;
#endif

#ifdef REGION_EYEBALL
    vec3 e = normalize(v_eye);
    float r = length(e.xy);
    float front = step(0.0, e.z);
    float aa = max(fwidth(r), 1e-4);
    float iris_mask = front * (1.0 - smoothstep(IRIS_RADIUS - aa, IRIS_RADIUS + aa, r));
    float pupil_mask = front * (1.0 - smoothstep(PUPIL_RADIUS - aa, PUPIL_RADIUS + aa, r));
    float t = clamp((r - PUPIL_RADIUS) / (IRIS_RADIUS - PUPIL_RADIUS), 0.0, 1.0);
    float turns = (atan(e.y, e.x) / (2.0 * PI) + 0.5) * float(IRIS_FIBRES);
    float fibre = 0.6 * value_noise(vec2(turns, t * 5.0), IRIS_FIBRES)
                + 0.4 * value_noise(vec2(turns * 0.5, t * 11.0 + 7.0), IRIS_FIBRES / 2);
    // Stroma: radial fibres, a lighter collarette around the pupil, crypts, and a dark
    // limbal ring; a little less saturated than the base colour (real irises are greyish).
    vec3 base_iris = mix(u_iris, vec3(dot(u_iris, vec3(0.3, 0.55, 0.15))), 0.25);
    vec3 iris = base_iris * (0.5 + 0.8 * fibre);
    iris *= mix(1.35, 1.0, smoothstep(0.12, 0.4, t));                // lighter collarette
    iris *= mix(1.0, 0.25, smoothstep(1.0 - LIMBUS_WIDTH, 1.0, t));  // dark limbal ring
    iris = mix(iris, u_pupil, pupil_mask);
    float theta = acos(clamp(e.z, -1.0, 1.0));
    // Off-white sclera, warmer and pinker toward the corners, with faint vessels.
    float vessels = smoothstep(0.72, 0.95, value_noise(vec2(atan(e.y, e.x) * 9.0, theta * 14.0), 0));
    vec3 sclera = u_sclera * vec3(0.93, 0.9, 0.87)
                * mix(vec3(1.0), vec3(1.0, 0.78, 0.74), smoothstep(0.6, 1.5, theta) + 0.3 * vessels * smoothstep(0.5, 1.0, theta));
    // The limbus blends softly into the sclera (no cut-out edge).
    float iris_soft = front * (1.0 - smoothstep(IRIS_RADIUS - aa - 0.015, IRIS_RADIUS + aa, r));
    vec3 albedo = mix(sclera, iris, max(iris_mask, 0.6 * iris_soft));
    // The upper lid and lashes shade the top third of the eyeball.
    float lid_shade = 1.0 - 0.45 * smoothstep(-0.1, 0.5, n.y);
    vec3 diffuse = diffuse_light(n, vec3(0.1), occ) * albedo * lid_shade;
    // Wet surface: a crisp corneal catch-light plus a broader sheen.
    vec3 spec = specular_light(n, v, 1600.0) * 0.35 + specular_light(n, v, 150.0) * 0.06;
    radiance = diffuse + spec * schlick(0.04, max(dot(n, v), 0.0)) * 8.0 * occ;
#endif

    // Inside the mouth the lips and cheeks shade everything; occlusion baked on a closed
    // mouth would black it out, so it only dims these regions down to a floor.
#ifdef REGION_TEETH
    // v_uv = (arc length from the midline in dm, 0 at the biting edge .. 1 at the gum line),
    // set per tooth vertex by facsim.head.proxies.teeth_coordinates (plain UV-less bands get 0).
    float arc = abs(v_uv.x);
    float h = clamp(v_uv.y, 0.0, 1.0);
    // Tooth boundaries along the arch (dm): incisors, laterals, canines, premolars.
    float b0 = 0.0, b1 = 0.0;
    if (arc < 0.085) { b0 = 0.0; b1 = 0.085; }
    else if (arc < 0.15) { b0 = 0.085; b1 = 0.15; }
    else if (arc < 0.225) { b0 = 0.15; b1 = 0.225; }
    else if (arc < 0.295) { b0 = 0.225; b1 = 0.295; }
    else { b0 = 0.295; b1 = 0.36; }
    float w = (arc - b0) / (b1 - b0);                     // 0..1 across this tooth
    // Thin interproximal lines, faded to a faint mean where they would be sub-pixel (small
    // images), so teeth never look dirty.
    float gap_aa = fwidth(arc);
    float gap_depth = 0.4 * clamp(1.5 - 120.0 * gap_aa, 0.0, 1.0);
    float gap = 1.0 - gap_depth * (1.0 - smoothstep(0.0, gap_aa + 0.0015, min(arc - b0, b1 - arc)));
    // Scalloped gum line: higher between teeth (papillae), lower over each crown.
    float gum_edge = 0.70 + 0.12 * (1.0 - sin(PI * clamp(w, 0.0, 1.0)));
    float gum = smoothstep(gum_edge - 0.04, gum_edge + 0.04, h);
    vec3 enamel = u_albedo * mix(vec3(0.86, 0.88, 0.92), vec3(1.0), smoothstep(0.02, 0.2, h));  // translucent edge
    enamel *= 0.92 + 0.08 * sin(PI * clamp(w, 0.0, 1.0));   // each crown is rounded
    vec3 albedo = mix(enamel * gap, vec3(0.62, 0.27, 0.28), gum);
    float mouth_shade = mix(0.85, 1.0, occ) * mix(1.0, 0.7, smoothstep(0.15, 0.36, arc));  // back teeth in shadow
    vec3 spec = specular_light(n, v, 90.0) * 0.18 * (1.0 - gum);
    // Enamel scatters light inside the tooth: a little of its own brightness beyond the lighting.
    radiance = ((diffuse_light(n, vec3(0.25, 0.2, 0.15), 1.0) + 0.18) * albedo + spec) * mouth_shade;
#endif

#ifdef REGION_TONGUE
    float mouth_shade = mix(0.45, 1.0, occ);
    vec3 spec = specular_light(n, v, 35.0) * 0.08;
    radiance = (diffuse_light(n, vec3(0.3, 0.15, 0.1), 1.0) * u_albedo + spec) * mouth_shade;
#endif

#ifdef REGION_MOUTH_INTERIOR
    // Mostly hidden and in the mouth's own shadow: dim, a little wet.
    float mouth_shade = mix(0.06, 1.0, occ * occ);  // falls off with depth (Face passes it in occ)
    vec3 spec = specular_light(n, v, 30.0) * 0.04;
    radiance = (diffuse_light(n, vec3(0.3, 0.1, 0.1), 1.0) * u_albedo * 0.55 + spec) * mouth_shade;
#endif

#ifdef REGION_LASHES
    radiance = diffuse_light(n, vec3(0.5), occ) * u_albedo;
    float t = clamp(v_lash, 0.0, 1.0);
    float x = v_pos.x * LASH_STRANDS_PER_DM;
    float strand = value_noise(vec2(x, 0.0), 0);
    float threshold = mix(0.3, 0.95, pow(t, 0.6));
    float aa = fwidth(strand) + 0.05;
    float hairs = smoothstep(threshold - aa, threshold + aa, strand);
    float mean = clamp(0.9 - 0.9 * t, 0.0, 1.0) * 0.7;
    alpha = mix(mean, hairs * (1.0 - 0.4 * t), clamp(2.0 - 2.0 * fwidth(x), 0.0, 1.0));
#endif

    f_color = vec4(finish(radiance).rgb, alpha);
}
