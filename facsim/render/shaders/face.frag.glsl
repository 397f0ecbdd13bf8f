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
uniform sampler2D u_tone;    // R periorbital darkening, G translucency, B pores, A sun (facsim.head.skin)
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
const float CORNEA_RADIUS = 0.49;  // radius of the cornea's curvature, 1.33 iris radii
const int IRIS_FIBRES = 96;        // radial noise cells around the iris
#endif

#if defined(REGION_TEETH) || defined(REGION_TONGUE)
#define ONE_ALBEDO
#endif
#ifdef REGION_TEETH
// Where each tooth ends along the arch (dm from the midline, per side): central and lateral
// incisor, canine, two premolars, two molars (mean adult crown widths, upper and lower).
const float UPPER_TEETH[8] = float[8](0.0, 0.085, 0.150, 0.225, 0.295, 0.360, 0.460, 0.560);
const float LOWER_TEETH[8] = float[8](0.0, 0.052, 0.108, 0.176, 0.246, 0.316, 0.426, 0.530);
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
    vec4 tone = texture(u_tone, v_uv);   // periorbital, translucency, pores, sun
    // Albedo varies at three scales, as photographed skin does, so no area is a flat plastic
    // colour: tone patches a couple of centimetres across (blood and melanin are never even),
    // blotches of a few millimetres, and grain about a millimetre across (pores and fine
    // lines, averaged; faded to its mean where it would be finer than a pixel; it also breaks
    // up the sheen below). All of it grows with age. (hm08's paint box is twice as long in v
    // as in u, hence the 1:2 frequencies: round cells.)
    vec2 grain_uv = v_uv * vec2(350.0, 700.0);
    float grain = mix(0.5, value_noise(grain_uv, 0),
                      clamp(2.0 - 1.2 * max(fwidth(grain_uv.x), fwidth(grain_uv.y)), 0.0, 1.0));
    float blotch = value_noise(v_uv * vec2(150.0, 300.0), 0);
    float patches = value_noise(v_uv * vec2(24.0, 48.0) + 17.0, 0);
    float mottle = 0.6 * blotch + 0.4 * grain;
    vec3 albedo = u_skin * (1.0 + vec3(0.10, 0.12, 0.13) * (1.0 + 1.2 * u_age) * (mottle - 0.5));
    albedo *= mix(vec3(1.04, 0.97, 0.96), vec3(0.975, 1.0, 1.02), patches);
    // Regional colour: redder nose, cheeks and ears (blood close to the surface), in broken
    // capillary patches rather than an airbrushed blob; darker, cooler skin around the eyes
    // (thin skin over vessels and muscle), more so with age; a shaved beard's blue-grey shadow.
    float red = detail.r * mix(0.45, 1.35, smoothstep(0.2, 0.8, 0.55 * blotch + 0.45 * patches));
    albedo *= mix(vec3(1.0), vec3(1.05, 0.80, 0.77), (0.7 + 0.3 * u_age) * red);   // older: broken veins
    albedo *= mix(vec3(1.0), vec3(0.78, 0.70, 0.75), tone.r * (0.6 + 0.5 * u_age));
    albedo = mix(albedo, albedo * vec3(0.70, 0.72, 0.78), u_beard * detail.g * (1.0 - paint.g));
    // Age spots: sparse, soft tan patches where the sun reaches, growing with age.
    float spot = smoothstep(0.72, 0.9, blotch) * tone.a * u_age;
    albedo *= mix(vec3(1.0), vec3(0.86, 0.76, 0.66), spot);
    albedo = mix(albedo, u_cheek, paint.a);
    albedo = mix(albedo, u_eyelid, paint.b);
    // Lips: the red is not a flat paint. Fine vertical furrows run across it (every 1.5 mm
    // or so along the lip, v; wavy along u), deeper with age and toward the middle of the
    // red; the colour is mottled; the vermilion border is a thin paler ridge (the "white
    // roll") where the red meets the skin, not a painted edge.
    float lips = paint.g;
    // (The blotches bend the furrows; each furrow gets its own depth from one hash, which
    // changes where the furrow pattern is zero, between furrows: no seam.)
    float lip_s = v_uv.y * 560.0 + 0.8 * blotch;
    float lip_line = pow(0.5 + 0.5 * cos(2.0 * PI * lip_s), 5.0)
                   * (0.25 + 0.75 * hash2(ivec2(int(floor(lip_s + 0.5)), 7)))    // uneven furrows,
                   * (0.3 + 0.7 * grain);                                         // broken along their length
    lip_line = mix(0.1, lip_line, clamp(1.6 - 3.0 * fwidth(lip_s), 0.0, 1.0));
    float lip_core = smoothstep(0.45, 0.95, lips);
    float border = lips * (1.0 - lips) * 4.0;
    vec3 lip_col = u_lips * (0.92 + 0.16 * blotch) * (1.0 - (0.28 + 0.2 * u_age) * lip_line * lip_core);
    albedo = mix(albedo, lip_col, smoothstep(0.0, 1.0, lips));
    albedo *= 1.0 + 0.07 * border * (1.0 - u_age);
#ifdef USE_BROWS
    vec2 brow = brow_hair(v_uv, paint.r);
#else
    vec2 brow = vec2(0.0, 1.0);
#endif
    float hair = brow.x;
    albedo = mix(albedo, u_brows * brow.y, hair);
    float cavity = 1.0 - 0.42 * u_age * detail.a;   // age lines and folds
#ifdef USE_WRINKLE
    cavity *= crease_shade(v_wrinkle, v_crease, v_uv);
#endif
#ifdef USE_PORES
    // Pores and fine relief: small pits and a finer orange-peel bump (surface gradient from
    // screen derivatives), strongest on the nose and cheeks (tone.b), deeper with age, faded
    // out where it would be finer than a pixel, so it never shimmers. Compiled only for large
    // images (render.py), where pores are bigger than a pixel.
    vec2 pore_uv = v_uv * vec2(700.0, 1400.0);   // cells ~0.5 mm, round (1:2, see the spots)
    float pit = smoothstep(0.55, 0.85, value_noise(pore_uv, 0));
    float pore_h = 0.5 * value_noise(pore_uv * 0.37 + 3.0, 0) - pit;
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    vec3 grad = sign(det) * (dFdx(pore_h) * r1 + dFdy(pore_h) * r2);
    float pore_fade = clamp(2.2 - 2.5 * max(fwidth(pore_uv.x), fwidth(pore_uv.y)), 0.0, 1.0);
    float pore_amount = pore_fade * (0.3 + 1.2 * tone.b) * (1.0 - paint.g) * (1.0 - hair);
    vec3 bumped = normalize(abs(det) * n - (0.0006 + 0.0003 * u_age) * pore_amount * grad);
    cavity *= 1.0 - 0.07 * pit * pore_amount;
#else
    // Micro-relief at small sizes: the skin's millimetre-scale unevenness (the mottle as a
    // height, surface gradient from screen derivatives: its cells span several pixels, so
    // the 2x2-quad derivative is smooth) tilts the normal a little, which breaks the sheen
    // into the irregular highlights of real skin instead of a plastic glaze.
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    vec3 grad = sign(det) * (dFdx(mottle) * r1 + dFdy(mottle) * r2);
    float relief = (0.0012 + 0.0008 * u_age) * (0.5 + tone.b) * (1.0 - paint.g) * (1.0 - hair);
    vec3 bumped = normalize(abs(det) * n - relief * grad);
#endif
    // Contact shadows: the baked visibility is close to 1 on the open face and falls only in
    // the nostrils, the lip line, the eye sockets and under the jaw; squaring it deepens
    // those small shadows (a soft studio key still reaches into them partly).
    float contact = occ * occ;
    // Subsurface look: light wraps past the terminator, red furthest, so the shadow edge is
    // soft and warm (less with age: thinner skin). Red scatters furthest under the skin, so it
    // sees the smooth normal; green and blue see the pores' relief (normal blending).
    vec3 wrap = vec3(0.42, 0.2, 0.14) * (1.0 - hair) * (1.0 - 0.3 * u_age);
    vec3 lit = diffuse_light(n, wrap, contact);
#ifdef USE_PORES
    lit.gb = mix(lit.gb, diffuse_light(bumped, 0.5 * wrap, contact).gb, 0.6);
#endif
#ifndef USE_PORES
    // The relief shades the key light too (first order in the tilt: cheap), mostly in green
    // and blue; red, scattered further under the skin, sees the smooth surface.
    lit += u_key_col * vec3(0.35, 1.0, 1.0) * (dot(bumped, u_key_dir) - dot(n, u_key_dir));
#endif
    // Light that scatters out of the skin's shadowed side is redder than the light going in.
    lit *= mix(vec3(1.0), vec3(1.06, 0.97, 0.95), (1.0 - contact) * (1.0 - hair));
    vec3 diffuse = lit * albedo;
    // Translucency: thin ears and nose wings glow red where the rim light comes from behind
    // them.
    float back_rim = clamp(dot(v, -normalize(u_rim_dir + 0.4 * n)), 0.0, 1.0);
    vec3 glow = back_rim * back_rim * u_rim_col * occ;
    diffuse += tone.g * 0.55 * glow * u_skin * vec3(1.0, 0.42, 0.3);
    // Specular in two lobes, as skin has: a broad one from the rough horny layer and a tight
    // one from the oil film. The film is patchy: the T-zone (detail.b) has most, in patches,
    // the cheeks little (matte), the lips are wet but broken by their furrows; brow hair has
    // none. Micro-relief (grain) breaks the sheen into a speckle instead of a plastic glaze,
    // and the rough surface keeps the grazing-angle Fresnel sheen low.
    float ndv = max(dot(n, v), 0.0);
    float fres = mix(0.028, schlick(0.028, ndv), 0.55);
    float oil = detail.b * (1.0 - 0.35 * u_age) * mix(0.55, 1.3, patches) * (1.0 - lips);
    // Wet, but the film is broken by the furrows and by the lips' fine mottle: a continuous
    // glossy band along the lip read as rubber.
    float wet = lips * (1.0 - 0.85 * lip_line) * (0.55 + 0.45 * blotch);
    // (The fill is too weak to show in a broad lobe: key and rim only.)
    float broad_shine = mix(8.0, 14.0, oil);
    vec3 broad = (blinn(bumped, u_key_dir, v, broad_shine) * u_key_col
                  + blinn(bumped, u_rim_dir, v, broad_shine) * u_rim_col) * mix(0.2, 0.75, oil);
    vec3 tight = blinn(bumped, u_key_dir, v, mix(32.0, 70.0, wet)) * u_key_col
               * (mix(0.08, 2.2, oil * oil) + 1.2 * wet);
    vec3 spec = (broad + tight) * fres * (1.0 - hair) * (0.4 + 1.2 * grain);
    radiance = (diffuse + spec * contact) * cavity;
#endif

#ifdef REGION_EYEBALL
    vec3 e = normalize(v_eye);
    float r = length(e.xy);
    float front = step(0.0, e.z);
    float aa = max(fwidth(r), 1e-4);
    float iris_mask = front * (1.0 - smoothstep(IRIS_RADIUS - aa, IRIS_RADIUS + aa, r));
    float pupil_mask = front * (1.0 - smoothstep(PUPIL_RADIUS - aa, PUPIL_RADIUS + aa, r));
    float t = clamp((r - PUPIL_RADIUS) / (IRIS_RADIUS - PUPIL_RADIUS), 0.0, 1.0);
    float angle = atan(e.y, e.x);
    float turns = (angle / (2.0 * PI) + 0.5) * float(IRIS_FIBRES);
    // Stroma: fine radial fibres (long along the radius, narrow around it), coarser crypts,
    // faded to their mean where they would be finer than a pixel (small images stay calm).
    float fibre = 0.55 * value_noise(vec2(turns, t * 3.0), IRIS_FIBRES)
                + 0.3 * value_noise(vec2(turns * 2.0, t * 1.5 + 3.0), IRIS_FIBRES * 2)
                + 0.15 * value_noise(vec2(turns * 0.25, t * 6.0 + 11.0), IRIS_FIBRES / 4);
    fibre = mix(0.5, fibre, clamp(1.6 - 0.6 * fwidth(turns), 0.0, 1.0));
    // A little less saturated than the base colour (real irises are greyish), a lighter
    // collarette ring a third of the way out, a dark pupillary ruff, and a dark limbal ring
    // at the rim that blurs into the sclera.
    vec3 base_iris = mix(u_iris, vec3(dot(u_iris, vec3(0.3, 0.55, 0.15))), 0.3);
    vec3 iris = base_iris * (0.5 + 1.0 * fibre);
    iris *= 1.0 + 0.35 * exp(-pow((t - 0.3) / 0.12, 2.0));
    iris *= mix(0.45, 1.0, smoothstep(0.0, 0.08, t));
    iris *= mix(1.0, 0.3, smoothstep(1.0 - LIMBUS_WIDTH, 1.0, t));
    iris = mix(iris, u_pupil, pupil_mask);
    float theta = acos(clamp(e.z, -1.0, 1.0));
    // Off-white sclera (never paper white): a touch warmer and pinker toward the corners
    // (conjunctival vessels, strongest nasally and temporally), with faint vessels there.
    float corner = smoothstep(0.4, 0.8, theta) * (0.55 + 0.45 * abs(cos(angle)));
    float vessels = smoothstep(0.7, 0.95, value_noise(vec2(angle * 9.0, theta * 14.0), 0)) * corner;
    // (Issue 13, reviewers: "glossy, doll-like eyes" - the sclera a touch greyer and warmer,
    // never brighter than the lit skin beside it.)
    vec3 sclera = u_sclera * vec3(0.78, 0.75, 0.72)
                * mix(vec3(1.0), vec3(1.0, 0.78, 0.72), 0.7 * corner + 0.5 * vessels);
    // Caruncle and plica: a pink fleshy fold fills the inner corner (e.x toward the nose:
    // -x for the eye on the +x side of the head).
    float nasal = front * smoothstep(0.45, 0.63, -sign(v_pos.x) * e.x);
    sclera = mix(sclera, u_sclera * vec3(0.82, 0.52, 0.5), 0.85 * nasal);
    // The limbus blends softly into the sclera as a greyish ring (no cut-out edge).
    float limbal = front * exp(-pow((r - IRIS_RADIUS) / 0.035, 2.0));
    sclera *= 1.0 - 0.35 * limbal;
    float iris_soft = front * (1.0 - smoothstep(IRIS_RADIUS - aa - 0.015, IRIS_RADIUS + aa, r));
    vec3 albedo = mix(sclera, iris, max(iris_mask, 0.6 * iris_soft));
    // The eyeball sits in the lids' shade. The thick upper lid and its lashes shadow a band
    // under its margin and the lower lid a little above its own: that shade follows the lids
    // in every frame and arrives in occ (Face.frame_occlusion, facsim.render.geometry.lid_shade),
    // so 5 bares lit sclera and 43 closes the shadow away. Here only what the lids cannot
    // say: the canthi shade the corners, and light falls off over the eyeball's curve toward
    // the orbit (eye frame: +y up, +x across the eye; at rest about e.y in [-0.2, 0.2] and
    // e.x in [-0.65, 0.65] show between the lids).
    // The socket around it hides much of the sky: the whole eyeball takes less ambient than
    // the skin.
    float lid_shade = 0.7 * (1.0 - 0.15 * smoothstep(-0.05, 0.3, e.y)) * (1.0 - 0.35 * smoothstep(0.3, 0.7, abs(e.x)));
    vec3 diffuse = diffuse_light(n, vec3(0.15), occ) * albedo * lid_shade;
    // Wet surface: a small soft catch-light on the cornea only, a faint broad sheen
    // elsewhere; no bright Fresnel rim (it made the eyes look like glass). The cornea bulges
    // over the iris as a sphere of 1.33 iris radii (7.8 mm over an 11.7-mm iris), so its
    // normal tilts faster than the eyeball's: the catch-light sits on the iris, not beside it.
    // (The eye frame is the world's while head and gaze are at rest; the tilt is added to the
    // world normal, exact at rest and close for the small turns of 51-58 and 61-64.)
    float cornea = front * (1.0 - smoothstep(IRIS_RADIUS - 0.02, IRIS_RADIUS + 0.02, r));
    vec2 bulge = e.xy / CORNEA_RADIUS;
    vec3 corneal = vec3(bulge, sqrt(max(1.0 - dot(bulge, bulge), 0.0)));
    vec3 nc = normalize(n + (corneal - e) * cornea);
    vec3 spec = specular_light(nc, v, 400.0) * 0.1 * cornea + specular_light(n, v, 40.0) * 0.025;
    radiance = diffuse + spec * mix(0.4, 1.0, lid_shade) * occ;
#endif

    // Inside the mouth the lips and cheeks shade everything; occlusion baked on a closed
    // mouth would black it out, so it only dims these regions down to a floor.
#ifdef REGION_TEETH
    // v_uv = (arc length from the midline in dm, height from the biting edge: 0 at the edge,
    // up the outer wall to 1 at the root row, down to -1 across the lingual slope; the lower
    // row adds 4), set per vertex by facsim.head.mouth.teeth_coordinates.
    float lower = step(2.0, v_uv.y);
    float h_signed = clamp(v_uv.y - 4.0 * lower, -1.0, 1.0);
    float h = max(h_signed, 0.0);              // up the outer (labial) wall
    float lingual = max(-h_signed, 0.0);       // in across the inside of the arch
    float arc = abs(v_uv.x);
    int kind = 0;
    for (int i = 1; i < 7; ++i) {
        if (arc >= mix(UPPER_TEETH[i], LOWER_TEETH[i], lower)) kind = i;
    }
    float b0 = mix(UPPER_TEETH[kind], LOWER_TEETH[kind], lower);
    float b1 = mix(UPPER_TEETH[kind + 1], LOWER_TEETH[kind + 1], lower);
    float w = clamp((arc - b0) / (b1 - b0), 0.0, 1.0);     // 0..1 across this tooth
    float side = abs(2.0 * w - 1.0);                        // 0 mid-crown .. 1 at its neighbours
    // The biting edge's outline, as the height (band units, ~1.6 cm) cut away below it:
    // incisors square with rounded corners (laterals a little shorter), canines a cusp,
    // premolars and molars cusps set higher (the curve of Spee). Cutting it out of the
    // band (discard) gives each tooth its own silhouette and the dark embrasures between.
    float notch;
    if (kind <= 1) {
        float corner = clamp((side - 0.45) / 0.55, 0.0, 1.0);
        notch = 0.035 * corner * corner + (kind == 1 ? mix(0.02, 0.01, lower) : 0.0);
    } else if (kind == 2) {
        notch = 0.06 * pow(side, 1.6) - 0.01;
    } else {
        // (Shallow: the back teeth's cusps show only in the buccal corridor's shade, where a
        // deep cut read as broken black teeth.)
        notch = 0.03 + 0.04 * pow(side, 3.0) + 0.01 * float(kind - 3);
    }
    // A band without coordinates (all (0, 0): constant, so no derivative) stays whole.
    bool shaped = fwidth(v_uv.x) + fwidth(v_uv.y) > 0.0;
    if (shaped && max(h, lingual) < notch) discard;
    // Each crown is convex: it turns away from the light toward its neighbours, and where two
    // touch they leave a soft shadow (an embrasure, deeper toward the biting edge where crowns
    // part) - never a dark line, which read as braces. Faded to a faint mean where it would be
    // finer than a pixel.
    float gap_aa = fwidth(arc);
    float to_gap = min(arc - b0, b1 - arc);
    float convex = 1.0 - 0.16 * pow(side, 3.0);
    float gap = 1.0 - 0.26 * (1.0 - smoothstep(0.0, gap_aa + 0.006, to_gap))
                    * clamp(1.5 - 120.0 * gap_aa, 0.3, 1.0) * mix(1.0, 0.45, smoothstep(0.1, 0.5, h));
    // Scalloped gum line, arched rootward over each crown (crowns ~10 mm of the band's 16),
    // papillae reaching toward the biting edge between crowns. A smile rarely shows it;
    // where it shows it is pink, lit like the teeth (no dark band under the lip).
    float gum_edge = mix(0.66, 0.58, lower) + mix(0.16, 0.14, lower) * sin(PI * w);
    // (Labial side only: the lingual gum lies deep in the arch's shade, and drawn pink it
    // showed as red dots between the lower crowns when 16 bared them.)
    float gum = smoothstep(gum_edge - 0.025, gum_edge + 0.025, h);
    // Ivory enamel: translucent at the edge (a little grey-blue where the dark mouth shows
    // through), warmer toward the neck where dentin shows, a little variation tooth to tooth.
    float tooth_id = float(kind) + 7.0 * step(0.0, v_uv.x) + 14.0 * lower;
    float vary = fract(sin(tooth_id * 12.9898) * 43758.5453);
    vec3 enamel = u_albedo * (0.96 + 0.06 * vary);
    enamel *= mix(vec3(0.82, 0.86, 0.92), vec3(1.0), smoothstep(notch, notch + 0.09, max(h, lingual)));
    enamel *= mix(vec3(1.0), vec3(1.0, 0.94, 0.83), smoothstep(0.3, gum_edge, h));
    vec3 gums = vec3(0.62, 0.27, 0.28) * (0.92 + 0.16 * value_noise(v_uv * vec2(60.0, 8.0), 0));
    vec3 albedo = mix(enamel * gap * convex, gums, gum);
    // Light inside the mouth falls off with depth: the front teeth catch it, the back ones sit
    // in the shadow of the cheeks (the dark buccal corridor). The upper lip casts a soft
    // contact shadow just under its edge: v_occlusion is the fragment's height (dm) below
    // that edge in this frame (facsim.head.mouth.mouth_light; 1 when nobody passes it). The
    // lower row stands back under the upper teeth and lip and faces up into the mouth:
    // darker, and mostly hidden.
    float depth_shade = mix(1.0, 0.16, smoothstep(0.12, 0.36, arc));
    float lip_shadow = mix(0.5, 1.0, smoothstep(-0.002, 0.022, v_occlusion));
    float row_light = mix(1.0, 0.62, lower);
    // The inside of the arch faces the tongue and throat: it only catches light scattered in.
    float mouth_shade = depth_shade * lip_shadow * row_light * mix(1.0, 0.12, smoothstep(0.0, 0.1, lingual));
    float wet = specular_light(n, v, 120.0).r * 0.35 + specular_light(n, v, 30.0).r * 0.05;
    vec3 spec = vec3(wet) * (1.0 - 0.6 * gum) * schlick(0.05, max(dot(n, v), 0.0)) * 3.0;
    // Enamel scatters light inside the tooth: a little of its own brightness beyond the lighting.
    radiance = ((diffuse_light(n, vec3(0.3, 0.25, 0.2), 1.0) * 0.9 + 0.16) * albedo + spec) * mouth_shade;
    // What light reaches the back teeth has bounced off the cheeks' red lining: warm, not grey.
    radiance *= mix(vec3(1.0, 0.6, 0.5), vec3(1.0), depth_shade);
#endif

#ifdef REGION_TONGUE
    // v_uv = (across -1..1, along 0 at the tip .. 1 at the root), facsim.head.mouth.tongue_coordinates.
    float across = v_uv.x, along = clamp(v_uv.y, 0.0, 1.0);
    // Median groove, papillae as fine mottling, a paler coat toward the middle.
    float groove = 1.0 - 0.35 * exp(-across * across / 0.012) * smoothstep(0.05, 0.3, along);
    float papillae = 0.85 + 0.3 * value_noise(v_uv * vec2(40.0, 60.0), 0);
    vec3 albedo = u_albedo * vec3(0.85, 0.72, 0.76) * papillae * groove;
    // The tongue lies in the shadow of the lips and upper teeth: dim at the tip, dark toward
    // the throat and at its sides against the teeth.
    // How much light the parted lips let in arrives in occ (facsim.head.mouth.mouth_light).
    float mouth_shade = mix(0.45, 0.05, smoothstep(0.0, 0.3, along)) * mix(1.0, 0.5, smoothstep(0.4, 1.0, abs(across)))
                      * mix(0.1, 1.0, occ);
    // Moist: a soft sheen broken by the papillae, and a tighter glint on the film of saliva.
    vec3 spec = specular_light(n, v, 40.0) * 0.12 * papillae + specular_light(n, v, 90.0) * 0.3 * smoothstep(0.8, 1.1, papillae);
    radiance = (diffuse_light(n, vec3(0.3, 0.15, 0.1), 1.0) * 0.8 * albedo + spec) * mouth_shade;
#endif

#ifdef REGION_MOUTH_INTERIOR
    // Mostly hidden and in the mouth's own shadow: dim, dark red, a little wet; falls off with
    // depth behind the lips (Face passes facsim.head.mouth.mouth_depth_visibility in occ) to
    // a warm, dull dark (light scattered through cheeks and lips), never black and never a
    // saturated red (seen through the gaps between the teeth, red read as braces' bands).
    float mouth_shade = occ * occ;
    vec3 spec = specular_light(n, v, 30.0) * 0.04;
    vec3 deep = 0.12 * mix(vec3(dot(u_albedo, vec3(0.33))), u_albedo, 0.5);
    radiance = (diffuse_light(n, vec3(0.3, 0.1, 0.1), 1.0) * u_albedo * 0.45 + spec) * mouth_shade
             + deep * (1.0 - mouth_shade);
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
