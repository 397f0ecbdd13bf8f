// Face fragment shader. One variant per region (render.py draws each region's faces with its
// own program, so a fragment runs only its region's code: on llvmpipe both sides of a branch
// cost, even when a uniform switches one off). Variants:
//   REGION_SKIN (+ USE_UV, USE_WRINKLE; + USE_BROWS for triangles under painted brows),
//   REGION_EYEBALL (+ USE_EYE, USE_LIDS), REGION_TEETH, REGION_TONGUE,
//   REGION_MOUTH_INTERIOR (+ USE_EYE: v_eye carries the cavity coordinates),
//   REGION_LASHES (+ USE_LASH), REGION_GARMENT (+ USE_UV: cloth coordinates; the body's clothes).
// All colour uniforms are linear RGB (render.py linearises the appearance's sRGB colours).

#include "common.glsl"
#include "shadow.glsl"

in vec3 v_pos;
in vec3 v_normal;
in float v_occlusion;
#ifdef USE_UV
in vec2 v_uv;
#endif
#if defined(REGION_SKIN) || defined(REGION_TONGUE)
in vec3 v_scatter_normal;   // the normal averaged over a few millimetres (Renderer: scattered_normals)
in float v_curvature;       // signed 1 / radius (dm^-1; < 0 in hollows), Renderer: surface_curvature
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
#ifdef USE_LIDS
in vec2 v_lids;   // degrees of eyeball arc below the upper lid's margin, above the lower's
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
// dims the ambient, fill and rim fully and the key partly; key_shadow (shadow.glsl) is the
// key's cast shadow. Without cast shadows the occlusion stands in for them in creases and
// sockets; with them it says how much of the large softbox a crease, a socket or the neck
// under the jaw still hides (the shadow map sees the key from its middle). (0.25 until session
// 25: a socket that sees two thirds of the room lost a tenth of the key, and the eyes sat in the
// face as brightly lit as the cheeks, the blind reviewer's "flat lighting".) Not on the eyeballs:
// their occlusion carries the lids' shade (USE_LIDS), finer than the map's texels resolve.
#if defined(USE_SHADOW) && !defined(REGION_EYEBALL)
const float KEY_OCCLUSION = 0.5;
#else
const float KEY_OCCLUSION = 0.6;
#endif
vec3 diffuse_light(vec3 n, vec3 wrap, float occ) {
    vec3 k = clamp((dot(n, u_key_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    vec3 f = clamp((dot(n, u_fill_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    vec3 r = clamp((dot(n, u_rim_dir) + wrap) / (1.0 + wrap), 0.0, 1.0);
    return k * u_key_col * key_shadow * mix(1.0, occ, KEY_OCCLUSION)
         + (f * u_fill_col + r * u_rim_col + hemisphere(n)) * occ;
}

vec3 specular_light(vec3 n, vec3 v, float shininess) {
    return blinn(n, u_key_dir, v, shininess) * u_key_col * key_shadow
         + blinn(n, u_fill_dir, v, shininess) * u_fill_col
         + blinn(n, u_rim_dir, v, shininess) * u_rim_col;
}

#ifdef REGION_SKIN
uniform sampler2D u_paint;   // R brow hair density, G lips, B eyelids, A cheek blush
uniform sampler2D u_detail;  // R redness, G beard area, B oiliness, A uneven pigment
const float FOLD_TEXELS = 3.0;   // a groove's half-width in fold-map texels (~0.8 mm each on the face)
const float FOLD_RELIEF = 1.6;   // height of the grooves and their rolls, of the map's groove depth
const vec2 CREVICE_SHADE = vec2(0.12, 0.05);   // shade at the floor: lines (R), under-eye lines (G)
const float GROOVE_SCATTER = 0.5;   // share of the grooves' slope the scattered light sees
const float FOLD_ASPECT = 0.5;   // the engine's furrows: roll height over spacing at FOLD_SPACING_REF (see main)
const float FOLD_SPACING_REF = 0.07;   // dm: the glabella's furrows
const float FURROW_SCATTER = 0.8;   // and of the engine's furrows' (rolls ~9 mm across: CREASES_PER_DM)
uniform sampler2D u_folds;   // R forehead lines + crow's feet, G under-eye lines, B fold shade,
                             // A where R and G replace the engine's furrows (facsim.head.skin)
uniform sampler2D u_tone;    // R darker skin (eyes, mouth, temples), G translucency, B pores, A sun (facsim.head.skin)
uniform float u_beard;       // 0..1 stubble shadow
uniform float u_beard_grey;  // 0..1 how grey the stubble is (facsim.head.appearance.Appearance)
uniform float u_age;         // 0..1 how much the age lines show
uniform vec3 u_skin;
uniform vec3 u_lips;
uniform vec3 u_brows;
uniform vec3 u_eyelid;
uniform vec3 u_cheek;
uniform float u_wrinkle_darken;
uniform float u_freckles;    // 0..1 freckle density on sun-exposed skin
uniform float u_redness;     // 0..2 scale of the redder areas
uniform float u_skin_seed;   // where this person's skin patterns fall

// Round spots scattered over a grid of cells (p in cell units): each cell holds at most one,
// with probability `prob`, at a random place and of a random radius up to `radius` (cell
// units). Returns (coverage 0..1, the spot's own random 0..1). Antialiased by the cell's
// size on screen; spots smaller than a pixel fade to their mean coverage.
vec2 spots(vec2 p, float prob, float radius, int salt) {
    vec2 cell = floor(p);
    ivec2 c = ivec2(cell) + ivec2(977 * salt, 613 * salt);
    float h = hash2(c);   // one hash per cell; its digits place and size the spot (cheap)
    vec2 centre = cell + 0.3 + 0.4 * fract(h * vec2(97.31, 53.17));
    float r = radius * (0.45 + 0.55 * fract(h * 7.31));
    float aa = max(fwidth(p.x), 1e-4);
    float cover = 1.0 - smoothstep(r - 0.6 * aa, r + 0.6 * aa, length(p - centre));
    cover = mix(PI * r * r, cover, clamp(3.0 * r / aa - 1.0, 0.0, 1.0));   // sub-pixel: mean
    return vec2(cover * step(h, prob), fract(h * 13.7));
}

// How much of a noise over cells of ``p``'s units shows: all of it where a cell spans two pixels
// or more, none where it is finer than about one (its mean there, or it shimmers).
float noise_detail(vec2 p) {
    return clamp(2.0 - 1.2 * max(fwidth(p.x), fwidth(p.y)), 0.0, 1.0);
}

// The aggregate of relief finer than a pixel (pores ~0.35 mm apart, the skin's fine lines): value
// noise over cells of ``p``'s units, evaluated at the octave whose cells are about two pixels
// across, its contrast scaled as the mean of that many finer cells varies (1/sqrt(N): halved per
// octave up). A pixel of a photograph holds a few pores and shows how many: skin keeps a fine
// grain, fixed to the surface, at any size; faded to its flat mean instead (as the grain below
// is), the skin at 448-512 px was an airbrushed glaze (issue 13: "smooth avatar skin"). Each
// octave has its own offset, so the pattern is continuous where the octave changes. Mean 0;
// standard deviation ~0.17 (value noise's) where the cells are 2 px or larger, half that per
// octave finer.
float pore_aggregate(vec2 p, float cells_per_px) {
    float lod = max(log2(cells_per_px) + 1.0, 0.0);
    float l0 = floor(lod);
    float f = lod - l0;
    float a = value_noise(p * exp2(-l0) + 7.31 * l0, 0) - 0.5;
    float b = value_noise(p * exp2(-l0 - 1.0) + 7.31 * (l0 + 1.0), 0) - 0.5;
    // (Two independent noises blended have less contrast than either: renormalised.)
    return mix(a, b, f) * inversesqrt(1.0 - 2.0 * f + 2.0 * f * f) * exp2(-lod);
}
float cells_per_pixel(vec2 p) {
    return max(max(length(dFdx(p)), length(dFdy(p))), 1e-6);
}
float pore_aggregate(vec2 p) {
    return pore_aggregate(p, cells_per_pixel(p));
}

// A shaved beard's shadow is the stubble's dark hairs seen in and through the skin, a follicle
// every half millimetre to millimetre (STUBBLE_CELLS: cells per texture unit, ~0.5 mm), so its cover
// varies from pixel to pixel as the number of hairs a pixel holds does (pore_aggregate: at 448 px a
// fine salt-and-pepper; at 1024 px specks a couple of pixels across), by STUBBLE_GRAIN per unit of
// the aggregate. (An even blue-grey tint over the beard's area read as paint on george and kwame;
// at 1-mm cells and 3.0 the stubble drew a camouflage of blotches.)
const vec2 STUBBLE_CELLS = vec2(700.0, 1400.0);
const float STUBBLE_GRAIN = 1.5;
// The stubble over the skin where it is full: dark hairs seen in and through the skin are a
// blue-grey shadow (DARK_STUBBLE, a multiplier); grey and white ones (u_beard_grey: the beard greys
// with the scalp hair) shade the skin less (their follicles' shadow, GREY_STUBBLE_SHADE) and cover a
// share of it (GREY_STUBBLE_COVER) in their own grey (GREY_STUBBLE, linear): a light skin greys and
// darkens, a dark one greys, a little lighter. (Until session 24 the dark hairs' blue-grey on every
// man: over george's sallow skin his lower face drew lilac. Until session 26 the shades were 0.70/
// 0.72/0.78 and 0.79, a multiplier both: the chin 6 L* darker, george taken for a woman, and
// kofi's white stubble did not show; a 0.4 cover of grey drew an ashen mask on him.)
const vec3 DARK_STUBBLE = vec3(0.56, 0.59, 0.68);
const vec3 GREY_STUBBLE = vec3(0.22, 0.21, 0.195);
const float GREY_STUBBLE_SHADE = 0.8;
const float GREY_STUBBLE_COVER = 0.2;
vec3 stubbled(vec3 albedo, float stubble) {
    vec3 grey = mix(albedo * GREY_STUBBLE_SHADE, GREY_STUBBLE, GREY_STUBBLE_COVER);
    return mix(albedo, mix(albedo * DARK_STUBBLE, grey, u_beard_grey), stubble);
}

// The skin's unevenness between the blotches and the regional maps (5-30 mm, what a photograph of
// a face at 448 px shows most): blood flushes the skin in irregular patches (more where the
// capillaries lie near the surface: ``redness``, the nose and cheeks), melanin lies in larger,
// softer ones (more of it in dark skin, which the flush hardly shows through). Returns the
// albedo's multiplier. (Without it the cheeks' hue varied at this scale by about 1.0 % against
// 1.8 % on a studio portrait's, skimage.data.astronaut(): an even tint, "waxy" to the reviewer.)
const float MID_FLUSH = 0.26;     // the flush's green and blue loss per unit of its noise
const float MID_PIGMENT = 0.12;   // the pigment's darkening per unit of its noise (2.6x in dark skin:
                                  // kwame's face of one even brown read as a mask)
const float AGED_PIGMENT = 1.0;
vec3 mid_tone(vec2 skin_uv, float redness, float melanin_rich) {
    // (Cells ~12 and ~6 mm for the flush, ~22 and ~9 mm for the pigment; 1:2 in u:v, round.)
    float flush = 0.6 * value_noise(skin_uv * vec2(30.0, 60.0) + 63.0, 0)
                + 0.4 * value_noise(skin_uv * vec2(60.0, 120.0) + 29.0, 0) - 0.5;
    float pigment = 0.65 * value_noise(skin_uv * vec2(16.0, 32.0) + 83.0, 0)
                  + 0.35 * value_noise(skin_uv * vec2(40.0, 80.0) + 47.0, 0) - 0.5;
    // (The forehead flushes less than the cheeks: mei's forehead, a patch of it, passed skin's C*.)
    float f = MID_FLUSH * flush * (0.4 + 1.6 * redness) * (1.0 - 0.7 * melanin_rich);
    vec3 tint = 1.0 - f * vec3(-0.15, 1.0, 0.85);
    // (Sun-aged skin's pigment is blotchier still, AGED_PIGMENT more per unit of u_age: sallow
    // yellow-brown patches, which george's even peach lacked.)
    return tint * (1.0 - MID_PIGMENT * (1.0 + 1.6 * melanin_rich + AGED_PIGMENT * u_age) * pigment * vec3(0.95, 1.0, 1.08));
}

// The share of the regional redness (the nose, the cheeks) that older skin keeps: young skin flushes
// nearly evenly; with age the flush gathers into the dilated capillaries of the nose and cheeks, in
// patches a few millimetres across (a noise of cells ~7 mm and the blotches', ~2 mm, ``blotch``:
// the flush's own 1.5-cm patches left a whole nose one pink) over skin that has gone sallow, where
// AGED_FLUSH_FLOOR of it is left (the noise under AGED_FLUSH_RANGE.x; all of it over .y). It scales
// both the regional redness and the mid-scale flush's (mid_tone). (Until session 24 the young
// skin's even flush at any age: george's nose tip at 448 px a* 21.7 (10.5 without the redness; now
// 14.6), his cheeks 16.0 (now 14.1) - the blind reviewer's "pink waxy skin" on 17 of his 26 images.)
const float AGED_FLUSH_FLOOR = 0.2;
const vec2 AGED_FLUSH_RANGE = vec2(0.45, 0.72);
float aged_flush(vec2 skin_uv, float blotch) {
    float n = 0.6 * value_noise(skin_uv * vec2(50.0, 100.0) + 37.0, 0) + 0.4 * blotch;
    return mix(1.0, mix(AGED_FLUSH_FLOOR, 1.0, smoothstep(AGED_FLUSH_RANGE.x, AGED_FLUSH_RANGE.y, n)), u_age);
}

// The most red over green the skin's diffuse light may carry where the mesh folds (see main), and
// where that is: 1 - cos of the angle between the surface's normal and the scatter normal (~10-26 deg).
const float REDDEST_SCATTER = 1.3;
const float MESH_FOLD_FROM = 0.015;
const float MESH_FOLD_FULL = 0.1;
// How much of each channel's diffuse light sees the scattered normal (v_scatter_normal) rather
// than the surface's own: red travels furthest under the skin, blue least.
const vec3 SCATTER_SOFTNESS = vec3(0.6, 0.3, 0.12);
// The shade's light comes out of the skin redder and more saturated (see main): SHADE_SCATTER_TINT
// multiplies the light other than the key's where it is most of the light, over SHADE_TINT_FROM to
// SHADE_TINT_FULL of it (the key's own shade: the nose's and jaw's undersides, the sides turned from it).
// On open skin the key lights (the fill there ~1/4 of the light) the albedo already is the colour of
// light that has come back out of the skin: tinting the fill there too made every lit face pinker
// (session 25: at 448 px the lit cheeks' fill light 4-7 % redder, R/G, than the key's, which is the
// warmer light; the cheeks at CIELAB C* 24-27, hue 49-52, above skin's 17-23 measured in vivo:
// "waxy" ava and mei, "plastic" liam). Green loses less than blue, as light filtered twice by the
// skin's own colour does (albedo squared: R/G up ~1.7 times as much as G/B), not a pink.
const vec3 SHADE_SCATTER_TINT = vec3(1.14, 0.93, 0.82);   // (0.92, 0.84 in G and B until session 26)
const float SHADE_TINT_FROM = 0.35;
const float SHADE_TINT_FULL = 0.8;
// The lips' sheen (skin_lobes): the vermilion's dry, lined surface gives only a faint broad lobe
// (weight LIP_LOBES.x, roughness LIP_BROAD_ROUGHNESS); the moist film, smoother than the skin's
// oil, a narrow one (LIP_ROUGHNESS) of weight LIP_LOBES.y where it is wet, broken by the furrows
// and in patches (wet in main). (Until session 22 a broad lobe of weight ~0.36 and roughness 0.6
// glazed the whole lower lip: "plastic lip sheen".)
const vec2 LIP_LOBES = vec2(0.2, 0.32);
const float LIP_BROAD_ROUGHNESS = 0.66;
const float LIP_ROUGHNESS = 0.3;
// The lips' colour fades into the skin's over the lip mask blurred to this mip level of the paint
// texture (level 4.5: a blur over ~23 of its 2048 rows), this share of it - the red fades over ~2 mm
// at the border on hm08's lips.
const float LIP_BORDER_LOD = 4.5;
const float LIP_BORDER_SOFTNESS = 0.6;
// The lips' deeper lines (session 26): at 448 px the fine furrows (~1.3 mm apart) are finer than a
// pixel and fade to their mean, and the red was one even surface, its sheen one glossy band ("rubbery
// lips or mouth", 18 of session 25's blind reviewer's notes). Lips at that size still show their deeper
// lines: fissures every LIP_FISSURE_SPACING of v (hm08's face UV, ~700 mm per v: ~3.5 mm), each its own
// depth (some barely there), bent by the blotches and broken along their length by the grain.
const float LIP_FISSURE_SPACING = 1.0 / 200.0;
const float LIP_FISSURE_SHADE = 0.3;   // how much darker a fissure's floor is
// A fissure is a fine groove (its profile cos^(2k), k = LIP_FISSURE_SHARPNESS: ~0.4 mm across); where
// that is finer than a pixel it is drawn as wide as the pixel and as much fainter (k lowered, the
// profile's area kept), so it still shows at 448 px, as the fine line it is, without aliasing.
// Returns (the groove's depth 0..1, how much of LIP_FISSURE_SHADE it takes): its relief shades it where
// it is resolved; where it is about a pixel wide or less, too fine for the relief to show, its shade
// stands for it (in close-ups a shaded floor as well drew each fissure as a dark band).
const float LIP_FISSURE_SHARPNESS = 24.0;
vec2 lip_fissures(float v, float bend, float grain) {
    float s = v / LIP_FISSURE_SPACING + 0.5 * bend;
    float pixel = max(fwidth(s), 1e-4);
    float k = min(LIP_FISSURE_SHARPNESS, 0.28 / (pixel * pixel));   // the profile at least a pixel wide
    float depth = hash2(ivec2(int(floor(s + 0.5)), 13));
    float line = pow(0.5 + 0.5 * cos(2.0 * PI * s), k) * sqrt(k / LIP_FISSURE_SHARPNESS);
    line *= smoothstep(0.25, 0.9, depth) * (0.5 + 0.5 * grain);
    return vec2(mix(0.05, line, clamp(1.6 - 3.0 * pixel, 0.0, 1.0)), smoothstep(0.02, 0.08, pixel));
}
// Ambient occlusion of the skin's hollows (see main): none where the surface curves inward less
// than CONCAVE_FROM dm^-1 (a 2-dm radius), CONCAVE_SHADE of the contact light lost at CONCAVE_FULL
// (a 2.5-cm radius: an eye socket's side, a nasolabial fold) and beyond.
const float CONCAVE_SHADE = 0.6;
const float CONCAVE_FROM = 0.5;
const float CONCAVE_FULL = 4.0;
// Melanin's tan over the skin (multipliers, linear): freckles and age spots are brown, a little
// darker than the skin and of about its hue - not the orange of (0.80, 0.66, 0.55), which the key's
// warmth and the skin's scattering turned into red dots (session 19's "rash" on george).
const vec3 FRECKLE = vec3(0.86, 0.78, 0.69);
const vec3 AGE_SPOT = vec3(0.88, 0.81, 0.72);
// Sun-weathered light skin (multiplier at full sun exposure and age): a little darker, its pink
// giving way to a sallow yellow-brown.
const vec3 WEATHERED = vec3(0.93, 0.89, 0.80);
// Pores (pore_aggregate): cells ~0.35 mm (hm08's face UV: ~350 mm per u, 700 per v), and how much
// they vary the skin's colour and break its sheen, per unit of the aggregate, on skin of average
// pore density (tone.b 0.4; the nose and the cheeks beside it more, the forehead's sides less).
const vec2 PORE_CELLS = vec2(1000.0, 2000.0);
// The fine noises' lattice turned ~33 degrees off the texture axes, which lie nearly along the
// image's rows and columns in a front view: value noise's cells aligned with the pixels drew the
// skin's grain and pores at 1024² as a mosaic of square blocks (issue 13: "blocky pores").
const mat2 GRAIN_TURN = mat2(0.839, 0.545, -0.545, 0.839);
const float PORE_TONE = 0.3;
const float PORE_SHEEN = 2.5;
// Where the pores are largest (tone.b: the nose and the cheeks beside it) the skin carries the most
// sebum (a pore's size follows its gland's output): its broad sheen is stronger there, up to
// PORE_SKIN_SHEEN more over PORE_SKIN_RANGE of tone.b, and broken by those pores (PORE_SHEEN), as a
// studio photograph shows the nose and the inner cheeks: a stippled sheen that says skin. (Until
// session 26 the nose's specular light at 448 px was 3 % of its light on ava, 9 % on kwame: a matte
// paint, with the face's only sheen on the forehead.)
const float PORE_SKIN_SHEEN = 1.2;
const vec2 PORE_SKIN_RANGE = vec2(0.45, 0.85);
// The sheen sees the skin's micro-relief (the grain's height below) SHEEN_RELIEF times as steep as
// the diffuse light does: light reflected at the surface sees every facet of the relief sharp,
// while light that scattered a millimetre or so under the skin before leaving sees it softened.
// So the T-zone's highlight breaks into a stipple of facets catching the light (a photograph's
// sheen at 448 px, pores and fine lines in aggregate) inside the lobe's envelope, instead of one
// smooth glaze: kwame's forehead highlight, blurred over 2 px, leaves 35 % of its energy in finer
// detail (21 % with the diffuse light's relief, until session 25: the blind reviewer's "plastic
// shiny skin / forehead sheen"; scripts/skin_figures.py "sheen fine").
const float SHEEN_RELIEF = 3.0;
// Mottling between ~2 and ~10 mm (cells ~5 and ~2.5 mm on hm08's face UV, turned off the texture
// axes as the grain is): the skin's lightness varies in soft blotches, a little warmer where
// darker (melanin), by MOTTLE_TONE per unit of the noise, light and dark skin alike. (Until
// session 25 the finest albedo variation above the grain was the blotches' ~2-mm cells at 0.6 of
// 10-13 %: mei's, liam's and amara's cheeks at 448 px an even, papery tone, "overly smooth",
// "waxy", "skin uniform"; scripts/skin_figures.py "fine tone". Twice as strong, 0.44, read as a
// camouflage of blotches on kwame.)
const float MOTTLE_TONE = 0.22;
vec3 skin_mottle(vec2 skin_uv) {
    float m = 0.55 * value_noise(GRAIN_TURN * (skin_uv * vec2(70.0, 140.0)) + 91.0, 0)
            + 0.45 * value_noise(GRAIN_TURN * (skin_uv * vec2(140.0, 280.0)) + 13.0, 0) - 0.5;
    return 1.0 + MOTTLE_TONE * m * vec3(0.9, 1.0, 1.1);
}

// Skin's specular (Fresnel F0 = SKIN_F0) from one light, in its two lobes (broad, tight):
// GGX distributions of the given roughness (by region: skin_lobes in skin_light.glsl, the tight
// lobe LIP_ROUGHNESS on the wet lips; alpha = roughness²) with Hammon's
// approximation of the height-correlated Smith visibility, times N.L.
const float SKIN_F0 = 0.028;
const float PEACH_FUZZ = 0.05;   // grazing sheen of the vellus hair, of the light reaching it
const float MUCOSA_SHINE = 0.3;                // its wet film's glint, of the light reaching it
                                               // (broad: a tight one broke into beads along the lip)
vec2 skin_specular(vec3 n, vec3 l, vec3 v, float ndv, vec2 roughness) {
    vec3 h = normalize(l + v);
    float ndl = max(dot(n, l), 0.0);
    float ndh = max(dot(n, h), 0.0);
    vec2 alpha = roughness * roughness;
    vec2 a2 = alpha * alpha;
    vec2 d = ndh * ndh * (a2 - 1.0) + 1.0;
    vec2 distribution = a2 / (PI * d * d);
    vec2 visibility = 0.5 / mix(vec2(2.0 * ndl * ndv), vec2(ndl + ndv), alpha);
    return distribution * visibility * (schlick(SKIN_F0, max(dot(v, h), 0.0)) * ndl);
}

// The key is a softbox about a metre across some 1.5 m away (half-angle ~0.3 rad), not a
// point: each point of skin reflects the whole box, so the key's highlight is the lobe spread
// by the box's size, broader and dimmer at its peak with the same light in all. (Lit by a point,
// an oily T-zone showed a small source's hot spot: a key at 40 degrees laid a white glaze on
// kwame's forehead, tests/test_skin.py.) The half-vector moves half as far as the light, so the
// box widens the GGX slope spread (alpha) by about half its half-angle, in quadrature (the
// spreads of two blurs add so); the wide, dry lobes hardly change, the oil film's tight one most.
const float KEY_SOFTBOX_HALF_ANGLE = 0.3;
vec2 softbox_roughness(vec2 roughness, float half_angle) {
    vec2 alpha = roughness * roughness;
    return sqrt(sqrt(alpha * alpha + 0.25 * half_angle * half_angle));
}

#ifdef USE_WRINKLE
// Creases as folds of skin, not painted lines (issue 13: "stamped/carved", "painted cheek
// wrinkles"): compressed skin buckles into rounded rolls with a soft valley between them. One
// valley at each whole number of the crease phase (v_crease, in furrow spacings), the phase bent
// by noise so the lines are not evenly spaced. The fold is a height profile across the furrows,
// its slope (Fold.slope) tilting the shading normal in main(): the light catches one flank and
// leaves the other in shade, so a fold's light and dark depend on where the light comes from;
// only the valley's floor darkens by itself (Fold.valley: less of the room reaches it).
// The lines are irregular: each has its own depth and length (a per-line share of a slow noise
// along it: some run long, some are short dashes, some hardly show), fine branch lines split
// off between them here and there, and every person's lines fall elsewhere (skin_uv). (Until
// session 25 every line was at least half as deep as the deepest and ran nearly the whole
// field: a smiling cheek drew four even parallel strokes, "painted cheek wrinkles".)
struct Fold {
    float slope;     // dH/ds: height change per furrow spacing, in furrow spacings (main() scales it)
    float valley;    // 0..1 how deep in a valley the point lies (occlusion)
    float s;         // the wavy phase (for its screen derivatives)
    float fold_amount;   // 0..1 how far the skin has folded
};
Fold crease_fold(float wrinkle, float phase, vec2 uv) {
    float s = phase + 0.3 * value_noise(uv * vec2(40.0, 25.0), 0) + 0.35 * value_noise(uv * vec2(11.0, 8.0) + 17.0, 0);
    float line = floor(s + 0.5);
    float t = s - line;                                       // -0.5 .. 0.5, valley at 0
    float aa = fwidth(s);
    int id = int(line) + int(7.0 * u_skin_seed);
    // Depth along the line: per line (hash) times a slow variation along it, which the line shows
    // in full only above its own threshold (its length) and at a quarter below it (a faint trace).
    float along = 0.7 * value_noise(uv * vec2(22.0, 44.0) + 9.0 * hash2(ivec2(id, 3)), 0)
                + 0.3 * value_noise(uv * vec2(55.0, 110.0) + 5.0 * hash2(ivec2(id, 5)), 0);
    float cut = mix(0.15, 0.5, hash2(ivec2(id, 13)));
    float depth = (0.45 + 0.55 * hash2(ivec2(id, 11))) * mix(0.25, 1.0, smoothstep(cut, cut + 0.3, along));
    // How far the skin has folded: from the engine's buckling threshold on (the wrinkle field is 0
    // below it), growing fastest at first (a buckled sheet's fold amplitude grows as the square
    // root of its extra compression) and levelling off (the folds close on themselves) - so an AU
    // at C (two thirds of E's compression) already shows its lines, and at E the folds deepen
    // without setting into uniformly cut grooves. (Until session 17 the lines started only at wrinkle 0.15 and
    // were full at 0.8: 9's nose lines, 0.13 at C, did not show at all.) Older skin creases
    // sooner (less elastic): the same compression shows more lines.
    float amount = (1.0 - exp(-wrinkle / (0.3 - 0.1 * u_age))) * smoothstep(0.0, 0.08, wrinkle);
    // The roll fades to flat where the furrows are finer than a few pixels (a pre-filter).
    float roll = clamp(2.0 - 4.0 * aa, 0.0, 1.0);
    // H(t) = -0.5 cos(2 pi t): the valley at t = 0, the rolls' crests half a spacing away.
    float dh_dt = PI * sin(2.0 * PI * t);
    // A fine branch line here and there on a roll's crest (t = +-0.5), where a second noise peaks.
    float tb = s - floor(s) - 0.5;
    float branch = smoothstep(0.62, 0.82, value_noise(uv * vec2(30.0, 60.0) + 13.0 * hash2(ivec2(id, 17)), 0));
    const float B = 0.07;
    float wb = max(B, 0.8 * aa);
    float dbranch = branch * 0.6 * (B / wb) * 2.0 * tb / (wb * wb) * exp(-(tb * tb) / (wb * wb));
    Fold f;
    f.slope = amount * roll * (depth * dh_dt + 0.12 * dbranch);
    f.valley = amount * depth * exp(-(t * t) / (2.0 * 0.12 * 0.12));
    f.s = s;
    f.fold_amount = amount;
    return f;
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
uniform float u_age;         // 0..1: 32 to 77 years (facsim.head.appearance)
// Both eyeballs' centres and radius this frame (Renderer._set_eye_centres; a lone eye: the
// same point twice): what belongs to the socket (caruncle, canthi) is placed from them, not
// from the eye's own frame, which turns with the gaze (61-64).
uniform vec3 u_eye_a = vec3(1.0, 0.0, 0.0);
uniform vec3 u_eye_b = vec3(-1.0, 0.0, 0.0);
uniform float u_eye_radius = 1.0;
// Each eye's own frame -> world this frame (Renderer._set_eye_centres; a mirrored frame is a
// reflection): the view seen from inside the eye, for the cornea's refraction and bulge.
uniform mat3 u_eye_rot_a = mat3(1.0);
uniform mat3 u_eye_rot_b = mat3(1.0);
// Radii as fractions of the eyeball radius, measured in the plane across the gaze axis
// (length of eye_coord.xy on the front half). hm08's eyeballs are 1.59 cm in radius:
// an iris 11.7 mm across (the adult mean) and the pupil of a studio portrait: 3.7 mm in a young
// adult, narrowing with age to 3.0 mm (senile miosis) (a 4-mm pupil, magnified by the cornea,
// left dark irises a thin rim around it: a doll's black disc, issue 13).
const float IRIS_RADIUS = 0.368;
const vec2 PUPIL_RADIUS = vec2(0.116, 0.094);   // young (u_age 0), old (u_age 1)
const float LIMBUS_WIDTH = 0.26;   // fraction of the iris annulus darkened at its rim ...
const float LIMBAL_RING = 0.4;     // ... to this much of its light at the rim
const float CORNEA_RADIUS = 0.49;  // radius of the cornea's curvature, 1.33 iris radii
// The iris lies in the anterior chamber, behind the cornea: the eyeball's sphere puts it
// only ~1.1 mm under the corneal apex, the apex is ~3.6 mm in front of it; this is the extra depth
// (eyeball radii) at the iris's centre, falling to nothing at the limbus. Seen through the
// cornea (refractive index 1.376), the iris shifts against the eyeball as the view turns.
const float ANTERIOR_CHAMBER = 0.15;
const float CORNEA_INDEX = 1.376;
const int IRIS_FIBRES = 96;        // radial noise cells around the iris
const float COLLARETTE = 0.33;     // where the collarette lies across the iris annulus (0 pupil, 1 rim)
const vec2 CARUNCLE = vec2(0.46, 0.56);   // nasal e.x where the caruncle begins and is full
const float SCLERA_MOTTLE = 0.1;    // the sclera's patchiness (relative, about its mean)
const float IRIS_SECTORS = 0.22;   // how much lighter or darker the iris's broad sectors are (about its mean)
const float IRIS_CAUSTIC = 0.3;    // how much brighter the iris's lower rim is (the key is above; 0.5 glowed as in a glass marble)
// The iris at 448-512 px, where its fibres have faded: the coarse bundles' share (0.3 until
// session 26, when its streaks were 4.6 % of its light on ava at 448 px: a smooth disc of glass),
// the collarette's zigzag (fraction of the annulus; 0.05 drew a round ring) and how much darker
// the pupillary zone inside it is (0.6 drew the dark ring of a target round the pupil).
const float IRIS_BUNDLES_ALONE = 0.85;
const float COLLARETTE_WAVE = 0.12;
const float PUPILLARY_ZONE = 0.3;
// The key's reflection in the cornea: the softbox's half-size (radians, across and up) and
// strength; the room's faint reflection over the whole cornea. (Issue 13: at 0.22 x 0.19
// with the fill's at 0.6, two large bright patches read as glossy doll's eyes.)
// (At 0.17 x 0.14, an even plate of ~1.1 mm² with a crisp edge, it still sat on the iris like a
// sticker: now a ~30-cm box at 1.2 m, ~0.5 mm² on the cornea, brightest in its middle, its rim
// fading out; 0.1 x 0.085 until session 26.)
const vec2 SOFTBOX = vec2(0.07, 0.085);
// Where the key's catch-light lies: the softbox's part that the cornea mirrors into view.
// The box is tall and stands to the side: seen from the eyes its lower, outer part lies at
// about 45 degrees to the side and 12 up (the key's centre: 28 and 38), so the catch-light sits
// on the iris at about 10 or 2 o'clock, half-way out, clear of the pupil.
// (Level with the eyes and 28 degrees out (SOFTBOX_DROP 0.64, no SOFTBOX_SIDE, sessions 24-25)
// it sat on the pupil's rim, half on the black disc: the painted highlight of a doll's or a
// cartoon's eye, issue 13 "glassy, doll eyes". Higher, it lay under the relaxed lids: on the
// hooded presets lids.yaml's most_cover_mm keeps it in view.)
const float SOFTBOX_DROP = 0.52;    // taken off the key direction's height (unit vector) ...
const float SOFTBOX_SIDE = 1.9;     // ... and its sideways part scaled by this
vec3 catch_light_direction(vec3 key_dir) {
    return normalize(key_dir * vec3(SOFTBOX_SIDE, 1.0, 1.0) - vec3(0.0, SOFTBOX_DROP, 0.0));
}
const float KEY_REFLECTION = 1.9;   // (0.65 for a box 2.8 times the area, 1.6 for one 1.06 times: the same light from a smaller box is brighter)
// The fill is a broad bounce card to the side: a larger, dimmer reflection (it shows where
// a lowered lid hides the key's, as in photographs).
const vec2 FILL_BOX = vec2(0.2, 0.3);
const float FILL_REFLECTION = 0.15;
// Coverage of a soft-edged rounded rectangle of half-size `size` (radians) centred on the
// light direction `l`, seen along the reflected ray `refl` (for catch-lights).
float softbox(vec3 refl, vec3 l, vec2 size) {
    vec3 bu = normalize(cross(l, vec3(0.0, 1.0, 0.0)));
    vec3 bv = cross(bu, l);
    vec2 q = vec2(dot(refl, bu), dot(refl, bv)) / size;
    // (Its soft edge widens by a pixel where the box is smaller than that, so small
    // images keep a catch-light instead of missing it between pixel centres.)
    float px = max(fwidth(q.x), fwidth(q.y));
    q *= q;
    float d = sqrt(sqrt(dot(q, q)));   // a superellipse: a rectangle with rounded corners
    return (1.0 - smoothstep(0.0, 1.3 + px, d)) * (0.7 + 0.3 * (1.0 - min(d, 1.0))) * step(0.0, dot(refl, l));
}
const float ROOM_REFLECTION = 0.035;
// Along the lids (degrees of eyeball arc from the margins, facsim.render.geometry.lid_elevations):
// the lower lid's wet rim and the tear line over it; the upper lid's shadow (depth, reach).
const float WET_RIM = 1.6;
const vec3 WET_RIM_COLOR = vec3(0.5, 0.25, 0.23);   // moist lid tissue (linear), whatever the skin
const float WET_RIM_SHEEN = 0.3;   // its film's reflection of the room
const float TEAR_WIDTH = 0.7;
const float TEAR_SHINE = 0.15;
const vec2 UPPER_SHADOW = vec2(0.65, 3.0);
// The lids' broader shade on the eyeball, as ambient occlusion (depth at the margin, reach in
// degrees: ~0.28 mm each on hm08); the lower lid's is lighter and shorter.
const vec2 UPPER_LID_SHADE = vec2(0.6, 8.0);
const vec2 LOWER_LID_SHADE = vec2(0.3, 4.0);
// The upper lid's soft cast shadow from the key above (depth at the margin, reach in degrees),
// on the eyeball's diffuse light only: an evenly lit eyeball to the lid's edge read as glass
// (0.3 deep left the iris's top as bright as its middle: still glassy).
// (The cornea's reflection of the key is the key seen past the lid: not shaded by it.)
// (At 0.45 over 8 degrees, with the lashes' shadow at 0.6 over 2.5 and the lower lid's shade at
// 0.2 over 3, the white that 5 bares above the iris in surprise was lit to 0.81-0.94 of the white
// beside the iris on liam and kwame (eyes_mouth_figures.py --aperture): an evenly lit ball in a
// ring of white, the reviewer's "bulging glassy eyes", issue 13; now 0.69-0.82.)
const vec2 UPPER_LID_CAST = vec2(0.55, 12.0);
#endif

#ifdef REGION_EYEBALL
// The eyeball's top, above the iris (hy: height above the eye's centre in eyeball radii),
// lies under the lid at rest; bared by 5 it is still deep under the brow ridge and the
// retracted lid fold, which hide most of the key above: in photographs of surprise and fear
// the white above the iris is a shaded band, and lit as brightly as beside the iris it read
// as an eyeball popping out (issue 13: "bulging eyes").
const vec2 ORBIT_SHADE = vec2(0.4, 0.5);   // how much darker at hy = ORBIT_SHADE.y; from hy 0.3
float orbit_shade(float hy) {
    return 1.0 - ORBIT_SHADE.x * smoothstep(0.3, ORBIT_SHADE.y, hy);
}
// The brow ridge and the upper lid's overhang hide the key above from the iris's upper half:
// its light falls off upward from below its middle (how much darker at its top, hy ~0.35).
// An iris lit evenly to its top (its top third 0.8-0.88 of its bottom's under 5) glowed as a
// lit disc in a ring of shaded white: a doll's glass eye (issue 13).
const float SOCKET_TOP_SHADE = 0.3;
float socket_top_shade(float hy) {
    return 1.0 - SOCKET_TOP_SHADE * smoothstep(-0.15, 0.35, hy);
}
#endif

#if defined(REGION_SKIN) || defined(REGION_MOUTH_INTERIOR)
const vec3 MUCOSA = vec3(0.40, 0.075, 0.09);   // the lips' mucosa (linear; sRGB ~ #aa4d54)
// The mucosa of darker lips: lighter and pinker than their vermilion, but by about this much in
// luminance, not by MUCOSA's own (darker skin carries melanin into the lips' lining too). Drawn
// in MUCOSA's one pink, 2.7 times as light as amara's lips, the lower lip's inner face over her
// lower teeth read as "red texture artifact in mouth" (blind review, session 23); lips lighter
// than the mucosa (light skin) keep MUCOSA.
const float MUCOSA_OVER_DARK_LIPS = 1.4;
vec3 mucosa_colour(vec3 lips) {
    return MUCOSA * min(1.0, MUCOSA_OVER_DARK_LIPS * dot(lips, LUMINANCE) / dot(MUCOSA, LUMINANCE));
}
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
#if defined(REGION_TONGUE) || defined(REGION_MOUTH_INTERIOR)
// Light that reaches deep into the mouth has bounced off red lining: warmed (the tongue's back
// and the cavity's walls alike).
const vec3 DEEP_BOUNCE = vec3(1.0, 0.7, 0.65);
#endif
#ifdef REGION_TONGUE
// The light an open mouth lets in falls off with depth behind the lips: about 1/e every
// TONGUE_LIGHT_FALLOFF of the tongue's length (~8 cm tip to root, so ~1.8 cm) from
// TONGUE_LIGHT_TIP at the tip, down to TONGUE_LIGHT_FLOOR, the light the cheeks and lips
// scatter in, itself fading toward the throat (to a third at the root, which rises under
// the palate's shadow). What reaches the back has bounced off the red lining: warm. (A steep fall to
// 0.015 by mid-tongue drew the tongue's back, which rises toward the throat and fills the
// upper half of a wide-open mouth, as one flat black: "a dark hole" cut by the tongue's
// crest in a hard line.)
const float TONGUE_LIGHT_TIP = 0.36;
const float TONGUE_LIGHT_FALLOFF = 0.3;
const float TONGUE_LIGHT_FLOOR = 0.1;
// How much of the tongue's shading normal is its normal averaged over ~2 rings of its mesh.
const float TONGUE_SMOOTHING = 0.8;
vec3 tongue_depth_light(float along) {
    float direct = exp(-along / TONGUE_LIGHT_FALLOFF);
    float scattered = TONGUE_LIGHT_FLOOR * (1.0 - 0.65 * smoothstep(0.3, 0.9, along));
    return (TONGUE_LIGHT_TIP * direct + scattered) * mix(DEEP_BOUNCE, vec3(1.0), direct);
}
#endif
#ifdef REGION_MOUTH_INTERIOR
// Deep in the mouth the lining takes only what light the cheeks and lips scatter in, after
// bouncing off more red lining: a dull, dark red-brown, as dark as the tongue's back
// (tongue_depth_light). (A greyed dark, 0.18 of the lining's colour half desaturated, drew
// the lining seen past the teeth at a wide mouth's corners as grey wedges, and the floor of
// the mouth under the tongue's tip as a black diamond in the muscle engine's 27.)
// That scattered light itself fades toward the throat: ``visibility`` (mouth_depth_visibility,
// exp(-depth / 1.8 cm), or the light through the parted lips, mouth.opening_light) takes it
// from 0.4 of the lining's colour just inside the lips down to CAVITY_BACK of that at the back
// of the mouth (~5 cm: 0.6 left at 1 cm, 0.3 at 3 cm), so the back of an open mouth is dark,
// as in photographs; uniform, the palate and the back wall were one flat dark red ("mouth
// interior flat"). (At 0.15 the back wall was near-black, luminance ~4-8 of 255, and with
// the throat's opening darker still the back of kwame's surprise read as a black hole; lit
// to CAVITY_BACK 0.45 the walls round the throat stay a dark red and the throat's opening
// (throat_shape) is the darkest part, as in photographs.)
const float CAVITY_BACK = 0.45;
const float ROOF_LIGHT = 0.35;
// Behind the lips, what light the opening lets in reaches the lining after bouncing off more
// red lining and the tongue: warm. (Lit by the room's light as it is, the back of a wide-open
// mouth, lit through the opening since session 23 (facsim.head.mouth.opening_light), was a
// grey-mauve curtain.) DEEP_BOUNCE, as on the tongue's back.
vec3 cavity_deep_colour(vec3 lining, float visibility) {
    return 0.4 * lining * vec3(1.0, 0.9, 0.9) * mix(CAVITY_BACK, 1.0, visibility);
}
// The back wall of the mouth is not one even surface: in its middle the throat opens (the
// oropharynx, under the soft palate's arch between its pillars), and from the arch's top the
// uvula hangs in front of that dark. A wide-open mouth in photographs shows that shape: the
// lining round it dark red, the opening near black, the uvula a lighter lobe at its top. Drawn
// as one even dark red the back read as a "dark flat mouth hole" (blind review, session 23: 9 of
// 156 images). In the back wall's coordinates (cavity_coordinates: across -1..1, up -1..1):
// the arch's centre and half-sizes, the uvula's length down from the arch's top and half-width.
const vec2 THROAT_CENTRE = vec2(0.0, -0.95);
const vec2 THROAT_SIZE = vec2(0.34, 0.8);
const vec2 UVULA = vec2(0.5, 0.11);
// The light left in the throat's opening, and on the uvula (its rounded front faces the opening).
const float THROAT_DARK = 0.3;
const float UVULA_LIGHT = 1.1;
// How the back of the mouth differs from an even wall at ``c`` (cavity_coordinates): x how much
// of the throat's dark opening is there (0..1), y how much uvula, z the soft palate's rim round
// the arch (lit a little more, its edge turned toward the opening).
vec3 throat_shape(vec3 c) {
    float back = smoothstep(0.75, 0.92, c.z);
    vec2 q = (c.xy - THROAT_CENTRE) / THROAT_SIZE;
    float r = length(q);
    float aa = max(fwidth(r), 0.02);
    float opening = 1.0 - smoothstep(0.7, 1.1 + aa, r);
    float top = THROAT_CENTRE.y + THROAT_SIZE.y;             // the arch's top
    float hang = (top - c.y) / UVULA.x;                      // 0 at the arch .. 1 at the tip
    float half_width = UVULA.y * (1.0 - 0.2 * hang) * sqrt(max(1.0 - pow(hang, 4.0), 0.0));   // a pendant, round-tipped
    float uvula = (1.0 - smoothstep(0.8 * half_width, half_width + 0.01, abs(c.x))) * step(0.0, hang) * step(hang, 1.0);
    float rim = smoothstep(0.75, 1.0, r) * (1.0 - smoothstep(1.0, 1.25, r));
    return back * vec3(opening * (1.0 - uvula), uvula * opening, rim);
}
#endif
#ifdef REGION_TEETH
// How far (band units, ~1.6 cm) the biting edge is cut back at ``side`` (0 mid-crown .. 1 at
// its neighbours) of a tooth of ``kind`` (0 central incisor .. 6 molar) in the upper
// (lower = 0) or lower row (1): incisors square with rounded corners, the upper laterals
// ~0.7 mm shorter than the centrals, so the upper front teeth part at their tips in small
// V-shaped embrasures (~1 mm), each crown its own outline; the lower incisors almost
// straight across (their embrasures, cut deep, showed the dark behind them as specks along
// the row's edge); canines a cusp; premolars and molars cusps set higher (the curve of Spee).
float incisal_notch(int kind, float side, float lower) {
    if (kind <= 1) {
        float corner = clamp((side - 0.35) / 0.65, 0.0, 1.0);
        return mix(0.06, 0.01, lower) * corner * corner + (kind == 1 ? 0.045 * (1.0 - lower) : 0.0);
    }
    if (kind == 2) return 0.06 * pow(side, 1.6) - 0.01;
    // (Shallow: the back teeth's cusps show only in the buccal corridor's shade, where a
    // deep cut read as broken black teeth.)
    return 0.03 + 0.04 * pow(side, 3.0) + 0.01 * float(kind - 3);
}
// Natural front teeth differ by kind, not by chance alone: the upper centrals are the largest and
// lightest, the laterals shorter (incisal_notch), a little darker and more translucent at the edge,
// the canines darker and yellower; and no biting edge is ruled straight. (With only a random spread
// per crown, every tooth one shape and nearly one shade, "teeth uniform", "too uniform and small",
// a blind reviewer on 12 of 78 images, session 24.) Per kind: (central, lateral, canine).
const vec3 TOOTH_KIND_VALUE = vec3(1.06, 0.9, 0.86);
const vec3 TOOTH_KIND_TRANSLUCENCY = vec3(1.0, 1.25, 0.7);
const vec3 TOOTH_KIND_YELLOW = vec3(0.0, 0.15, 0.8);
// How much shorter than its kind each incisor's edge is (band units, ~16 mm: up to ~0.25 mm), and how
// far its edge tilts across the crown (up to ~0.3 mm from one corner to the other): worn, uneven edges;
// half as much on the lower row, whose edges, seen from above, show the dark behind them.
const vec2 INCISAL_UNEVEN = vec2(0.015, 0.02);
float incisal_unevenness(float tooth_id, float w) {
    float shorter = hash2(ivec2(int(tooth_id), 61));
    float tilt = 2.0 * hash2(ivec2(int(tooth_id), 67)) - 1.0;
    return INCISAL_UNEVEN.x * shorter + INCISAL_UNEVEN.y * 0.5 * (1.0 + tilt * (2.0 * w - 1.0));
}
// Each crown is convex: its middle faces the light and its flanks turn away toward its
// neighbours, brightness varying by this much across it about the same mean (0.08, darkening
// only the flanks, drew the row as one flat white strip at 448 px).
const float CROWN_ROUNDING = 0.18;
// The light left on a tooth right under the upper lip's edge and in the mouth's corners,
// where the lips and cheeks wrap the teeth (facsim.head.mouth.mouth_light). (At 0.5 the
// back teeth of a stretched mouth (20+26) showed as grey slabs in its corners.)
const float LIP_SHADOW_FLOOR = 0.3;
// Teeth behind lips that barely part (heights shifted under -0.7 dm: mouth_light's SLIT_SHIFT)
// keep this fraction of that floor: a slit lets in little light, and the gap between closed
// lips reads as a dark shade, not as grey teeth.
const float CLOSED_LIPS_DARK = 0.15;
// What light the cheeks and lips scatter into the mouth reaches its back teeth too, after
// bouncing off the red lining: the deepest teeth keep this much of their colour, warmed
// (DEEP_TEETH_BOUNCE), as the tongue's back does (TONGUE_LIGHT_FLOOR). Without it the lower
// row's back teeth and the inside of its arch, which a stretched open mouth (20+26) shows in
// its corners, were pure black wedges with straight edges (issue 13: "molar wedges").
const float DEEP_TEETH_LIGHT = 0.04;
// The lips and cheeks round the opening hide much of the room from the teeth: the fill and
// the sky reach them with this visibility (the key with KEY_OCCLUSION of the loss). Lit as
// fully as the face (visibility 1, plus a glow of 0.16 for the enamel's scattering), a
// smile's teeth stood 1.3 times the cheek's L* (~82 against 63 at 512 px): a white strip
// "inserted" in the face. In photographs the teeth in the mouth are about as light as the
// lit skin beside it.
const float TEETH_AMBIENT = 0.75;
const float ENAMEL_GLOW = 0.06;
// The share of that light the enamel returns. (0.9 was set while the biting edge's normals
// pointed down, averaged with the band's lingual fold, which darkened every crown toward its
// edge; with the edge lit as the front it faces (render.geometry.teeth_normal_operator), 0.9
// drew a smile's teeth at L* ~83, 1.39 times the cheek's: glowing. Natural teeth in
// photographs are L* ~65-80, lighter than the skin but not by a third.)
const float TEETH_DIFFUSE = 0.58;
// What light reaches the enamel inside the mouth has partly bounced off the lips, gums and
// tongue: warm. (Dimmed without it, the crowns turned grey, not ivory: C* ~11 at L* ~73.)
const vec3 INSIDE_WARMTH = vec3(1.0, 0.98, 0.95);
// How far the biting edge's translucent band turns to the blue-grey of the dark behind it
// (0.65 drew the upper laterals and canines, whose edges are cut back, as grey-blue slabs).
const float INCISAL_TRANSLUCENCY = 0.4;
const vec3 DEEP_TEETH_BOUNCE = vec3(1.0, 0.42, 0.38);
// Natural teeth differ: each crown's value by up to TOOTH_SHADE_SPREAD.x (a quarter of it brighter
// or darker than the albedo) and its yellowing toward TOOTH_YELLOW by up to TOOTH_SHADE_SPREAD.y;
// toward the gum the dentin shows through the thinner enamel (TOOTH_CERVICAL, at the neck).
const vec2 TOOTH_SHADE_SPREAD = vec2(0.16, 0.4);
const vec3 TOOTH_YELLOW = vec3(1.0, 0.95, 0.84);
const vec3 TOOTH_CERVICAL = vec3(0.97, 0.87, 0.7);
// Where the gum begins on each crown's outer wall (band units up from the biting edge): upper row
// between the crowns (the papillae's tips), at mid-crown (the zenith); lower row the same.
const vec4 GUM_LINE = vec4(0.45, 0.65, 0.4, 0.56);
// Where two crowns touch they leave a soft shadow (an embrasure) ``to_gap`` (dm) from the
// contact, darkest at the biting edge where they part and a thin shade up the crowns to the
// gum (``h``, band units up the outer wall) - never a dark line, which read as braces; faded
// to a faint mean where it would be finer than a pixel (``aa``, dm per pixel). The lower
// row's edges stay light: seen from above, their embrasures read as dark specks.
// The crown's normal ``n`` tilted by its bulge's ``slope`` (its height's rate of change along the
// arch, away from the midline) toward ``along`` (the arch's direction there). The slope is the
// bulge's own derivative and the direction is taken from the smooth normal, so the tilt is as
// smooth as they are: from screen derivatives of the bulge, constant over each of hm08's coarse
// triangles, the crowns were shaded in flat facets (issue 13: "teeth look inserted"), and where a
// pixel quad straddled the band's fold at the biting edge the gradient spiked into dark specks.
vec3 crown_normal(vec3 n, vec3 along, float slope) {
    vec3 t = normalize(cross(vec3(0.0, 1.0, 0.0), n) + vec3(1e-6, 0.0, 0.0));
    t *= sign(dot(t, along) + 1e-12);
    return normalize(n - slope * t);
}
// (EMBRASURE_SHADE 0.35, up the crowns 0.6 of it: the crowns ran together into one strip.)
const float EMBRASURE_SHADE = 0.5;
// Up the upper crowns, where two teeth touch, their embrasure keeps this much of its shade at the
// edge. (0.75 drew a grey line the crown's full height between every pair of teeth, evenly
// spaced: at 448 px the row read as "smeared like a grille"; the crowns now part by their
// own sheen and rounding, ENAMEL_SHEEN. The lower row's, seen from above, keeps as little or
// it reads as a grille.)
const float EMBRASURE_UP_CROWN = 0.4;
// Wet enamel mirrors the studio's large frontal lights: a soft vertical sheen down the middle of
// each crown (ENAMEL_SHEEN_WIDTH of its width), where its bulge faces the light, fading onto the
// flanks and toward the gum, and only where the crown faces the camera. (The crowns' normals
// never come within ~20 degrees of the view, the labial faces leaning back, so a mirror lobe
// about the view missed them.) Without it the crowns were matte, one flat beige from the edge
// to the lip ("teeth blurry", "yellow blur", 14 of the blind reviewer's 156 images); the sheen
// parts the crowns where grey lines between them read as a grille.
const float ENAMEL_SHEEN = 0.18;
const float ENAMEL_SHEEN_WIDTH = 0.22;
// The lower crowns face up into the mouth: their sheen is this share of the upper's (before the
// row's shade), and what light reaches them has bounced off the tongue and the lower lip, pink.
// (Dimmed ivory alone is olive: with no sheen and that cast, fear's bared lower row read as a
// khaki band of evenly parted slabs, "odd gum colour".)
const float LOWER_ROW_SHEEN = 0.6;
const vec3 LOWER_ROW_BOUNCE = vec3(1.0, 0.95, 0.96);
float embrasure_shade(float to_gap, float aa, float h, float lower) {
    float at_edge = mix(1.0, 0.5, lower);
    return EMBRASURE_SHADE * (1.0 - smoothstep(0.0, aa + 0.008, to_gap)) * clamp(1.5 - 120.0 * aa, 0.3, 1.0)
         * mix(at_edge, EMBRASURE_UP_CROWN, smoothstep(0.04, 0.25, h));
}
#endif
#if defined(ONE_ALBEDO) || defined(REGION_MOUTH_INTERIOR) || defined(REGION_LASHES) || defined(REGION_GARMENT)
uniform vec3 u_albedo;
#endif
#ifdef REGION_MOUTH_INTERIOR
uniform vec3 u_lips;         // the lining just inside the lips is their mucosa (mucosa_colour)
#endif

#ifdef REGION_LASHES
// Lashes are drawn last, blended. render.py puts each lash vertex's root-to-tip coordinate
// (0 at the lid, 1 at the tip: distance from the nearest eyeball centre, normalised per lash
// strip) in in_wrinkle's slot. Strands are a stripe pattern along world x (the lid line in
// the head's frame) whose strands end at random lengths, so the lash strips read as tapering
// hairs rather than a dark band.
const float LASH_STRANDS_PER_DM = 300.0;
#endif

#ifdef REGION_GARMENT
const float FOLD_SPACING = 0.34;  // dm between the folds' ridges along the neckline
const float FOLD_DEPTH = 0.06;    // dm
const float FOLD_LENGTH = 5.0;    // band widths below the neckline where they have faded
const float FOLD_REACH = 0.5;     // dm along the neckline from the front where they fade
#endif

#include "skin_light.glsl"

void main() {
    vec3 n = surface_normal();
    vec3 v = normalize(u_cam_pos - v_pos);
    float occ = clamp(v_occlusion, 0.0, 1.0);
    float alpha = 1.0;
    vec3 radiance;
#ifdef USE_SHADOW
    key_shadow = vec3(key_visibility(v_pos, n));
#endif

#ifdef REGION_SKIN
    vec4 paint = texture(u_paint, v_uv);
    vec4 detail = texture(u_detail, v_uv);
    vec4 tone = texture(u_tone, v_uv);   // darker skin, translucency, pores, sun
    // Albedo varies at three scales, as photographed skin does, so no area is a flat plastic
    // colour: tone patches a couple of centimetres across (blood and melanin are never even),
    // blotches of a few millimetres, and grain about a millimetre across (pores and fine
    // lines, averaged; faded to its mean where it would be finer than a pixel; it also breaks
    // up the sheen below). All of it grows with age. (hm08's paint box is twice as long in v
    // as in u, hence the 1:2 frequencies: round cells.)
    // Each person's patterns lie elsewhere on the noise (u_skin_seed), so no two share a skin.
    vec2 skin_uv = v_uv + vec2(0.0731, 0.0419) * u_skin_seed;
    vec2 grain_uv = GRAIN_TURN * (skin_uv * vec2(350.0, 700.0));
    vec3 grain_noise = value_noise_grad(grain_uv);   // (its slope: the micro-relief below)
    float grain_detail = noise_detail(grain_uv);
    float grain = mix(0.5, grain_noise.x, grain_detail);
    // (The lips keep the grain on the texture's axes, which their furrows, along v, follow; off
    // the lips, nearly all pixels, it is skipped.)
    vec2 lip_grain_uv = skin_uv * vec2(350.0, 700.0);
    float lip_grain_detail = noise_detail(lip_grain_uv);   // (derivatives outside the branch)
    float lip_grain = paint.g > 0.0 ? mix(0.5, value_noise(lip_grain_uv, 0), lip_grain_detail) : 0.5;
    float blotch = value_noise(skin_uv * vec2(150.0, 300.0), 0);
    float pores = pore_aggregate(GRAIN_TURN * (skin_uv * PORE_CELLS));
    float patches = value_noise(skin_uv * vec2(24.0, 48.0) + 17.0, 0);
    float mottle = 0.6 * blotch + 0.4 * grain;
    vec3 albedo = u_skin * (1.0 + vec3(0.10, 0.12, 0.13) * (1.0 + 1.2 * u_age) * (mottle - 0.5));
    albedo *= mix(vec3(1.04, 0.97, 0.96), vec3(0.975, 1.0, 1.02), patches);
    // (Their openings hold keratin and sebum, yellow-grey: they vary the skin's lightness, a
    // little less its redness, or at 448 px their grain read as fine red dots.)
    albedo *= 1.0 + PORE_TONE * (0.6 + tone.b) * pores * vec3(1.15, 1.0, 0.9);
    // The variation is in the skin's two pigments, not a grey noise: blood (haemoglobin takes
    // green and blue) gathers in irregular flushed patches about a centimetre across, broken
    // up by the blotches, and melanin lies unevenly in larger, softer patches (darker, a
    // little warmer). Melanin veils the blood in dark skin, whose unevenness is mostly its
    // pigment's.
    float lum_skin = dot(u_skin, LUMINANCE);
    float melanin_rich = 1.0 - smoothstep(0.05, 0.3, lum_skin);
    float haem = 0.55 * value_noise(skin_uv * vec2(55.0, 110.0) + 5.0, 0) + 0.45 * blotch;
    albedo *= mix(vec3(1.0), vec3(1.01, 0.86, 0.87), (0.9 - 0.5 * melanin_rich) * smoothstep(0.4, 0.85, haem));
    albedo *= 1.0 - (0.05 + 0.07 * melanin_rich) * (patches - 0.5) * vec3(0.85, 1.0, 1.15);
    albedo *= skin_mottle(skin_uv);
    float capillaries = aged_flush(skin_uv, blotch);   // (older skin's flush in patches)
    albedo *= mid_tone(skin_uv, detail.r * u_redness * capillaries, melanin_rich);
    // Regional colour: redder nose, cheeks and ears (blood close to the surface), in broken
    // capillary patches rather than an airbrushed blob; darker, cooler skin around the eyes
    // (thin skin over vessels and muscle), more so with age; a shaved beard's blue-grey shadow.
    // Mild: a nose or cheek a shade redder than the skin around it, never pink (a saturated
    // nose tip read as painted); melanin veils much of it in dark skin.
    float veil = mix(0.45, 1.0, smoothstep(0.03, 0.3, dot(u_skin, LUMINANCE)));
    float red = u_redness * detail.r * veil * mix(0.6, 1.25, smoothstep(0.2, 0.8, 0.55 * blotch + 0.45 * patches));
    // (Older: broken veins, a little more. Until session 20 (1.03, 0.84, 0.83) at up to 1.05x the
    // map: george's nose and cheeks read as flushed, a sore red.) With age the flush breaks up
    // (aged_flush): ruddy patches over sallow skin, not one even pink.
    albedo *= mix(vec3(1.0), vec3(1.02, 0.87, 0.87), min((0.75 + 0.15 * u_age) * red, 1.0) * capillaries);
    albedo *= mix(vec3(1.0), vec3(0.78, 0.70, 0.75), tone.r * (0.6 + 0.5 * u_age));
    // The same darker areas (tone.r: around the eyes and the mouth, temples, hairline, the
    // jaw's sides) hold more pigment in melanin-rich skin: darker still, unevenly (a dark
    // face of one even brown read as a plastic mask).
    albedo *= 1.0 - tone.r * mix(0.6, 1.3, patches) * 0.3 * melanin_rich * vec3(0.85, 1.0, 1.15);
    float stubble = u_beard * detail.g * (1.0 - paint.g);
    vec2 stubble_uv = GRAIN_TURN * (skin_uv * STUBBLE_CELLS) + 11.0;
    float stubble_px = cells_per_pixel(stubble_uv);   // (derivatives outside the branch)
    // (A branch: llvmpipe skips it for the blocks of pixels outside a man's beard.)
    if (stubble > 0.0) {
        stubble *= clamp(1.0 + STUBBLE_GRAIN * pore_aggregate(stubble_uv, stubble_px), 0.0, 2.0);
    }
    albedo = stubbled(albedo, stubble);
    // Age spots (solar lentigines): sparse, soft tan patches a few millimetres to a centimetre
    // across where the sun reaches, growing with age. (Until session 20 they were the peaks of the
    // few-mm blotches, an orange multiplier: on george's forehead a rash of small red-brown dots.)
    float lentigo = 0.7 * value_noise(skin_uv * vec2(60.0, 120.0) + 41.0, 0) + 0.3 * blotch;
    float spot = smoothstep(0.74, 0.92, lentigo) * tone.a * u_age;
    // Decades of sun weather the exposed skin (forehead, nose, cheekbones: tone.a) of light skin
    // darker and yellower (solar elastosis), unevenly (the pigment's patches).
    albedo *= mix(vec3(1.0), WEATHERED, tone.a * u_age * (1.0 - melanin_rich) * (0.6 + 0.8 * patches));
    albedo *= mix(vec3(1.0), AGE_SPOT, spot);
    // Freckles (cells ~2.5 mm, spots ~1 mm, denser where the sun reaches) and a few moles and
    // small red marks anywhere on the face (cells ~12 mm): no real skin is without them,
    // and they are what makes one person's skin their own.
    float sun = tone.a * (1.0 - paint.g);
    vec2 freckle = spots(skin_uv * vec2(140.0, 280.0), u_freckles * smoothstep(0.05, 0.6, sun), 0.3, 1);
    albedo *= mix(vec3(1.0), FRECKLE, freckle.x * (0.3 + 0.4 * freckle.y));
    vec2 mark = spots(skin_uv * vec2(30.0, 60.0), 0.06 * (1.0 - paint.g) * (1.0 - paint.b), 0.09, 2);
    albedo *= mix(vec3(1.0), mix(vec3(0.55, 0.42, 0.36), vec3(1.0, 0.78, 0.76), step(0.55, mark.y)), mark.x);
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
                   * (0.3 + 0.7 * lip_grain);                                     // broken along their length
    lip_line = mix(0.1, lip_line, clamp(1.6 - 3.0 * fwidth(lip_s), 0.0, 1.0));
    vec2 fissures = lip_fissures(v_uv.y, blotch, lip_grain);
    float fissure = fissures.x;
    // Inside the wet-dry line the lips roll into their mucosa (detail.a, facsim.head.mouth.
    // lip_mucosa): smooth (no furrows), wet, a deeper and more bluish red than the vermilion
    // (unpigmented: pink-red on dark lips too). Hidden where the closed lips touch, it is the
    // band an open mouth shows between the lips' red and the dark inside.
    float mucosa = detail.a;
    lip_line *= 1.0 - mucosa;
    fissure *= 1.0 - mucosa;
    float lip_core = smoothstep(0.45, 0.95, lips);
    float border = lips * (1.0 - lips) * 4.0;
    vec3 lip_col = u_lips * (0.92 + 0.16 * blotch) * (1.0 - (0.16 + 0.16 * u_age) * lip_line * lip_core)
                 * (1.0 - LIP_FISSURE_SHADE * fissures.y * fissure * lip_core);
    // Toward the vermilion border the red thins into the skin's own colour (a painted-on
    // colour with an even edge read as a rubber mask).
    lip_col = mix(mix(albedo, u_lips, 0.6), lip_col, lip_core);
    // The vermilion border is a soft edge: the red fades into the skin over a millimetre or two
    // (the mask blurred: its mip LIP_BORDER_LOD); just inside it the red is a little paler.
    // (Until session 20 the red stopped within the mask's own ~0.5 mm: at 448 px a cut-out,
    // "a separate salmon-coloured object" on the face.)
    float lips_soft = textureLod(u_paint, v_uv, LIP_BORDER_LOD).g;
    albedo = mix(albedo, lip_col, smoothstep(0.0, 1.0, mix(lips, lips_soft, LIP_BORDER_SOFTNESS)));
    albedo *= 1.0 + 0.03 * border * (1.0 - u_age);   // (faint: a bright rim outlined the lips)
    albedo = mix(albedo, mix(u_lips, mucosa_colour(u_lips), 0.8) * (0.9 + 0.2 * blotch), mucosa);
#ifdef USE_BROWS
    vec2 brow = brow_hair(v_uv, paint.r);
#else
    vec2 brow = vec2(0.0, 1.0);
#endif
    float hair = brow.x;
    albedo = mix(albedo, u_brows * brow.y, hair);
    // Folds of skin (u_folds): the forehead lines and crow's feet, the under-eye lines, the
    // nasolabial and marionette folds, as soft grooves 3-5 mm across, not painted strokes: their
    // sloping sides shade them (lit on one flank, in soft shade on the other) and their floor
    // darkens only a little. Age shows them; the forehead lines and crow's feet also deepen
    // where the skin is pushed together (raised brows for the forehead, the raised cheek of 6
    // for the crow's feet: the lines of a young face show only then). The nasolabial and
    // marionette folds are a soft shade on the cheek's side (the smile's deepening fold is in
    // the geometry), not a line.
    vec4 folds = texture(u_folds, v_uv);
#ifdef USE_WRINKLE
    float line_depth = min(u_age + 1.1 * smoothstep(0.03, 0.35, v_wrinkle), 1.4);
#else
    float line_depth = u_age;
#endif
    // Only a crevice's floor, narrower than the groove (its depth profile to the 6th power: ~1.2
    // mm either side), darkens: light reaches it only from a narrow cone. (Until session 19 the
    // whole 3-5-mm groove darkened by 10 % of its depth, its lit flank too: under the frontal key
    // the lines drew as dark brown-red strokes, the reviewer's "painted forehead wrinkles".)
    vec2 floor_g = folds.rg * folds.rg;
    floor_g *= floor_g * floor_g;
    float cavity = (1.0 - CREVICE_SHADE.x * floor_g.x * line_depth - CREVICE_SHADE.y * floor_g.y * u_age)
                 * (1.0 - 0.12 * u_age * folds.b);
    // Surface frame for bump mapping from screen derivatives (Mikkelsen's surface gradient):
    // a height h tilts the normal to normalize(|det| n - sign(det) (dh/dx r1 + dh/dy r2)).
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    vec3 n_smooth = n;
    // The grooves' slopes (up to ~2.5 mm deep, dm) come from the map alone, their depth held
    // constant across them: the wrinkle amount is interpolated per triangle, and its slope
    // broke the grooves into facets where 6 squeezes the outer eye corner. They fade out where
    // they would be narrower than about two pixels (a pre-filter: the slope is constant over
    // each 2x2 pixel quad, so narrower grooves would break into light and dark blocks).
    vec2 texel = v_uv * vec2(textureSize(u_folds, 0));
    float groove_px = FOLD_TEXELS / cells_per_pixel(texel);
    vec2 depth = vec2(-0.018 * line_depth, -0.006 * u_age) * clamp(groove_px - 1.5, 0.0, 1.0);
    // The skin a groove gathers is pushed up beside it into rolls: the height is the grooves less
    // the same map blurred over ~4x their width (its mip level two up), so the surface between
    // two lines bulges into a roll whose lower half faces down, into soft shade, as a compressed
    // forehead's does, instead of lying flat between sunk grooves.
    // The grooves' slope per pixel: the map's differences over a texel along u and v, carried to
    // the screen by the texture coordinates' derivatives (constant over a triangle). (The map's
    // own screen derivatives are one value per 2x2-pixel quad: at 1024 px the crow's feet broke
    // into staircases of light and dark blocks, drawn lines rather than relief.) The rolls (the
    // map two mip levels up) likewise, over four texels.
    // (Central differences: one-sided ones put the flanks' light and shade half a texel off the
    // crevice's floor.)
    // (Only where the map has folds nearby, its blur two mip levels up not zero, and they show
    // (depth: a young face's lines only where an AU compresses the skin): a branch, which llvmpipe
    // skips for the blocks of pixels away from them, most of the face.)
    vec2 fold_step = 1.0 / vec2(textureSize(u_folds, 0));
    vec2 rolls = texture(u_folds, v_uv, 2.0).rg;
    mat2 fold_uv = mat2(0.0);   // columns: the grooves less the rolls, per texel along u and along v
    if (dot(rolls, abs(depth)) > 0.0) {
        vec2 du = vec2(0.5 * fold_step.x, 0.0), dv = vec2(0.0, 0.5 * fold_step.y);
        fold_uv = mat2(texture(u_folds, v_uv + du).rg - texture(u_folds, v_uv - du).rg
                       - 0.25 * (texture(u_folds, v_uv + 4.0 * du, 2.0).rg - texture(u_folds, v_uv - 4.0 * du, 2.0).rg),
                       texture(u_folds, v_uv + dv).rg - texture(u_folds, v_uv - dv).rg
                       - 0.25 * (texture(u_folds, v_uv + 4.0 * dv, 2.0).rg - texture(u_folds, v_uv - 4.0 * dv, 2.0).rg));
    }
    vec2 uv_dx = dFdx(v_uv) / fold_step, uv_dy = dFdy(v_uv) / fold_step;   // texels per pixel
    vec2 fold_dx = FOLD_RELIEF * (fold_uv * uv_dx);
    vec2 fold_dy = FOLD_RELIEF * (fold_uv * uv_dy);
    float dh_dx = dot(fold_dx, depth), dh_dy = dot(fold_dy, depth);
    vec3 groove_grad = sign(det) * (dh_dx * r1 + dh_dy * r2);
    n = normalize(abs(det) * n - groove_grad);
#ifdef USE_WRINKLE
    // The engine's furrows, except where the fold map draws the lines itself (folds.a).
    Fold fold = crease_fold(v_wrinkle * (1.0 - folds.a) * (1.0 - mucosa), v_crease, skin_uv);
    // Less of the room reaches a valley's floor (and blood is pushed together there): the shade
    // lies in the valleys, not over the whole compressed patch like a stain.
    // (Where the fold map draws the lines (folds.a) they deepen with the compression as relief,
    // line_depth above, and its crevices' floors shade themselves.)
    cavity *= 1.0 - u_wrinkle_darken * clamp(v_wrinkle, 0.0, 1.0) * (0.35 + 1.6 * fold.valley);
    // A deep fold's valley closes into a narrow shadowed floor (the old crevice, softer and only
    // where the skin has folded far).
    cavity *= 1.0 - 0.25 * fold.fold_amount * fold.valley;
    // The fold's height over its spacing grows with the spacing: fine lines (the crow's feet's
    // 5 mm, the nose's 4.5 mm) are shallow, the glabella's and the forehead's broad furrows deep.
    // At a fixed height (until session 25) the finer the lines the steeper and darker they drew:
    // the nose's sides "sculpted", the cheeks' lines "painted". (fold_dir: the phase's surface
    // gradient, of length |det| / spacing.)
    // (Where the phase turns back, its gradient vanishes and the spacing it implies is unbounded:
    // capped, the slope fades out there instead of flipping in a hard seam.)
    vec3 fold_dir = dFdx(fold.s) * r1 + dFdy(fold.s) * r2;
    float relative = min(abs(det) / max(length(fold_dir), 1e-12) / FOLD_SPACING_REF, 1.0);
    float aspect = FOLD_ASPECT * max(relative, 0.5);
    vec3 fold_grad = sign(det) * aspect * fold.slope * FOLD_SPACING_REF * relative * fold_dir;
    n = normalize(abs(det) * n - fold_grad);
#endif
#ifdef USE_PORES
    // Pores and fine relief: small pits and a finer orange-peel bump (surface gradient from
    // screen derivatives), strongest on the nose and cheeks (tone.b), deeper with age, faded
    // out where it would be finer than a pixel, so it never shimmers. Compiled only for large
    // images (render.py), where pores are bigger than a pixel.
    // (Their slope is the noise's own, per pixel, carried to the screen by the texture
    // coordinates' derivatives: screen derivatives of the height, one per 2x2-pixel quad, drew the
    // pores at 1024² as a mosaic of 2-px blocks, issue 13: "blocky pores".)
    vec2 pore_uv = GRAIN_TURN * (v_uv * vec2(700.0, 1400.0));   // cells ~0.5 mm, round (1:2, see the spots)
    vec3 pore_noise = value_noise_grad(pore_uv);
    vec3 bump_noise = value_noise_grad(pore_uv * 0.37 + 3.0);
    float pit = smoothstep(0.55, 0.85, pore_noise.x);
    float pit_slope = smoothstep_slope(0.55, 0.85, pore_noise.x);
    vec2 pore_slope = 0.5 * 0.37 * bump_noise.yz - pit_slope * pore_noise.yz;   // d height / d pore_uv
    vec3 grad = sign(det) * (dot(pore_slope, dFdx(pore_uv)) * r1 + dot(pore_slope, dFdy(pore_uv)) * r2);
    float pore_fade = clamp(2.2 - 2.5 * max(fwidth(pore_uv.x), fwidth(pore_uv.y)), 0.0, 1.0);
    float pore_amount = pore_fade * (0.3 + 1.2 * tone.b) * (1.0 - paint.g) * (1.0 - hair);
    // (0.8 of the height the pores had with a slope per quad: the same mean step between pixels.)
    vec3 bumped = normalize(abs(det) * n - (0.00048 + 0.00024 * u_age) * pore_amount * grad);
    vec3 sheen_n = bumped;   // (the pores' own relief: at this size the sheen already breaks on them)
    cavity *= 1.0 - 0.07 * pit * pore_amount;
    float spec_break = 1.0 - 0.6 * pit * pore_amount;   // pores hold no oil film facing the light
#else
    // Micro-relief at small sizes: the skin's millimetre-scale grain as a height (surface
    // gradient from screen derivatives) tilts the normal a little, which breaks the sheen
    // into the irregular highlights of real skin instead of a plastic glaze. Only the grain:
    // the blotches' few-millimetre cells as a height drew a network of lit and shaded cell
    // walls over the cheek, a craquelure rather than skin (issue 13, ava's raised cheek in
    // 6+12 most of all); the blotches stay in the colour.
    // Pores show at this size too where they are largest (nose, the cheeks beside it, less on
    // the forehead and chin: tone.b), as a speckle of small pits about a millimetre apart that
    // darken a little and break the sheen; faded to nothing where they would be finer than a
    // pixel. (Shallow: pixel-sized pits as deep as a pore read as red dots, blotchy skin; at
    // 0.04 and only where tone.b passed 0.3 the skin at 768² read as airbrushed wax, issue 13.)
    // (The grain's own peaks, so no further noise is evaluated; it is already faded to its
    // flat mean where it would be finer than a pixel.)
    // (The slope per pixel from the noise's own gradient, as the pores' above.)
    float pore_share = smoothstep(0.15, 0.8, tone.b) * (1.0 - paint.g) * (1.0 - hair);
    float pit = smoothstep(0.62, 0.9, grain) * pore_share;
    float pit_slope = smoothstep_slope(0.62, 0.9, grain);
    vec2 relief_slope = (0.4 - 0.6 * pore_share * pit_slope) * grain_detail * grain_noise.yz;   // d height / d grain_uv
    vec3 grad = sign(det) * (dot(relief_slope, dFdx(grain_uv)) * r1 + dot(relief_slope, dFdy(grain_uv)) * r2);
    // (Its height 0.6 of what it was with a slope per quad, which averaged the slope over 2x2 pixels:
    // the same mean step between pixels, 0.0125 on an oily patch at 448 px, and no more red dots where
    // the relief shades green and blue more than red.)
    float relief = (0.00096 + 0.00048 * u_age) * (0.5 + tone.b) * (1.0 - paint.g) * (1.0 - hair);
    vec3 bumped = normalize(abs(det) * n - relief * grad);
    vec3 sheen_n = normalize(abs(det) * n - SHEEN_RELIEF * relief * grad);   // (the sheen's: see SHEEN_RELIEF)
    cavity *= 1.0 - 0.09 * pit;
    float spec_break = 1.0 - 0.7 * pit;   // pores hold no oil film facing the light
#endif
    // The lips' furrows are grooves (~0.1 mm deep), not only darker lines: their slopes catch
    // the key on one flank and break the lips' sheen into short strokes, so the red reads as
    // soft, lined tissue rather than smooth rubber.
    float lip_h = -0.0012 * (1.0 + 0.5 * u_age) * max(lip_line, fissure) * lip_core;
    vec3 lip_grad = sign(det) * (dFdx(lip_h) * r1 + dFdy(lip_h) * r2);
    bumped = normalize(abs(det) * bumped - lip_grad);
    sheen_n = normalize(abs(det) * sheen_n - lip_grad);
    // Contact shadows: the baked visibility is close to 1 on the open face and falls only in
    // the nostrils, the lip line, the eye sockets and under the jaw; squaring it deepens
    // those small shadows (a soft studio key still reaches into them partly).
    // Hollows shade themselves too, at a scale the baked visibility is too coarse for: where the
    // surface curves inward (v_curvature < 0) it sees less of the room and the softbox, so the
    // eye sockets beside the nose, the nasolabial folds, the mouth's corners and the hollow under
    // the lower lip keep their depth under the frontal key (CONCAVE_SHADE; issue 13: "flat").
    // (The curvature's sign is the mesh normal's, which surface_normal() turns toward the viewer on
    // back faces (a mirrored mesh's winding): turned with it, a hollow is a hollow either way.)
    float hollow = gl_FrontFacing ? -v_curvature : v_curvature;
    float contact = occ * occ * (1.0 - CONCAVE_SHADE * smoothstep(CONCAVE_FROM, CONCAVE_FULL, hollow));
    // Subsurface look: light wraps past the terminator, red furthest, so the shadow edge is
    // soft and warm (less with age: thinner skin); only a little, as skin scatters light a
    // few millimetres and too much wrap is what looks waxy. Red scatters furthest under the
    // skin, so it sees the smooth normal; green and blue see the pores' relief.
    vec3 wrap = vec3(0.3, 0.13, 0.08) * (1.0 - hair) * (1.0 - 0.3 * u_age) * scatter_reach(v_curvature);
    // Light entering a fold's shaded flank or a crease comes out a few millimetres away, so
    // the surface's small relief (the mesh's folds and the drawn grooves) shades red least and
    // blue most: folds look soft and warm, not carved in grey (v_scatter_normal is the normal
    // averaged over two rings of neighbours, ~1 cm).
    vec3 n_scatter = normalize(gl_FrontFacing ? v_scatter_normal : -v_scatter_normal);
    vec3 n_scatter_mesh = n_scatter;
    // The drawn grooves and rolls are 3-5 mm across, about as far as red light travels under the
    // skin, not the centimetre the averaged normal smooths over: the scattered light sees half
    // their slope. (Seeing none of it, the grooves' shade was all green and blue: red lines.)
    // The engine's furrows' rolls (crease_fold) are ~9 mm across, well beyond red's reach: the
    // scattered light sees most of their slope. (Seeing none of it, the line over the brows in 1+2
    // drew as a pink stroke, issue 13, session 21: over a strip across it at 1024², its shade's C*
    // over the strip's median +3.3 until session 22, +2.2 at half the slope, +1.5 now.)
#ifdef USE_WRINKLE
    n_scatter = normalize(abs(det) * n_scatter - GROOVE_SCATTER * groove_grad - FURROW_SCATTER * fold_grad);
#else
    n_scatter = normalize(abs(det) * n_scatter - GROOVE_SCATTER * groove_grad);
#endif
    vec3 softness = SCATTER_SOFTNESS * (1.0 - hair);
    // (The key only: it alone draws the small relief's light and shade; the fill, rim and
    // sky are broad and dim, and a second full evaluation cost ~10 % of a video frame.)
    skin_shadow_edge((1.0 - hair) * (1.0 - 0.6 * melanin_rich));
    vec3 key_reach = u_key_col * key_shadow * mix(1.0, contact, KEY_OCCLUSION);
    vec3 key_sharp = clamp((dot(n, u_key_dir) + wrap) / (1.0 + wrap), 0.0, 1.0) * key_reach;
    vec3 key_part = mix(key_sharp, clamp((dot(n_scatter, u_key_dir) + wrap) / (1.0 + wrap), 0.0, 1.0) * key_reach,
                        softness);
    vec3 lit = diffuse_light(n, wrap, contact) + key_part - key_sharp;
    // Light in the shade reaches the eye after travelling through the skin: all but the
    // direct key (fill, sky, rim) comes out redder and more saturated, as in photographs,
    // where skin in shadow is a deeper red-brown and never the grey of a painted surface.
    // (Melanin absorbs much of the scattered light in dark skin: less reddening there.)
    float scatter = (1.0 - hair) * smoothstep(0.03, 0.3, dot(u_skin, LUMINANCE));
    float shade_share = 1.0 - dot(key_part, LUMINANCE) / max(dot(lit, LUMINANCE), 1e-4);   // (the fill's, rim's, room's)
    lit = key_part + (lit - key_part) * mix(vec3(1.0), SHADE_SCATTER_TINT,
                                            scatter * smoothstep(SHADE_TINT_FROM, SHADE_TINT_FULL, shade_share));
#ifdef USE_PORES
    lit.gb = mix(lit.gb, diffuse_light(bumped, 0.5 * wrap, contact).gb, 0.6);
#endif
#ifndef USE_PORES
    // The relief shades the key light too (first order in the tilt: cheap), mostly in green
    // and blue; red, scattered further under the skin, sees the smooth surface.
    lit += u_key_col * key_shadow * vec3(0.35, 1.0, 1.0) * (dot(bumped, u_key_dir) - dot(n, u_key_dir));
#endif
    // Subsurface scattering reddens the terminator: where the key grazes the surface, light
    // that entered on the lit side comes out beyond it, its green and blue absorbed on the way.
    float key_cos = dot(n_scatter, u_key_dir);
    lit += u_key_col * key_shadow * vec3(0.075, 0.018, 0.006) * exp(-key_cos * key_cos * 16.0) * contact * scatter;
    // Light that scatters out of the skin's shadowed side is redder than the light going in.
    lit *= mix(vec3(1.0), vec3(1.06, 0.97, 0.95), (1.0 - contact) * (1.0 - hair));
    // Where the mesh itself folds (4's furrow between the brows, the line over the brows in 1+2),
    // its normal turns away from the centimetre-wide scatter normal within a few millimetres: the
    // red sees the scatter normal and the full wrap while green and blue see the flank, and the
    // flank turned from the key drew as a saturated red stroke (issue 13: "sharp reddish mesh
    // creases", "painted"). Light that has come through the skin there is redder than the light
    // that went in, but only so much (REDDEST_SCATTER: red over green at most that of the shade's
    // scattered ambient): the fold is a shade, darker in all three channels and a little warmer.
    // (Only where the normals part: broad curves and terminators keep their red wrap.)
    float mesh_fold = smoothstep(MESH_FOLD_FROM, MESH_FOLD_FULL, 1.0 - dot(n, n_scatter_mesh));
    lit.r = mix(lit.r, min(lit.r, REDDEST_SCATTER * lit.g), mesh_fold);
    // Nor is it bluer than a shade: where the averaged normal turns away from the key while the
    // skin itself faces it (the rim of 5's raised upper lid, whose normals run down into the
    // socket), red, which sees the averaged normal most, lost most of the key and the strip
    // over the eyeball drew teal-grey (lit 0.50, 0.64, 0.63 on liam's fear): a glassy rim along
    // the lid (issue 13, "glassy eyes"). Scattered light comes out at least as red as it went in.
    lit.r = mix(lit.r, max(lit.r, lit.g), mesh_fold);
    vec3 diffuse = lit * albedo;
    // Translucency: thin ears and nose wings glow red where the rim light comes from behind
    // them.
    float back_rim = clamp(dot(v, -normalize(u_rim_dir + 0.4 * n)), 0.0, 1.0);
    vec3 glow = back_rim * back_rim * u_rim_col * occ;
    diffuse += tone.g * 0.55 * glow * u_skin * vec3(1.0, 0.42, 0.3);
    // Specular in two GGX lobes, as measured on skin: a broad one from the rough horny layer,
    // over the whole face (roughness 0.53 on the T-zone to 0.66 on the cheeks: skin_lobes), and
    // a tighter one from the oil film, with
    // Fresnel from skin's reflectance at normal incidence (F0 = 0.028, IOR 1.4). The weights
    // sum to about one, so skin stays mostly diffuse with a broad soft sheen. The film is thin
    // and only where the skin is oiliest (detail.b: the forehead's middle, the nose, the chin),
    // uneven but not in specks (a speckled film of tight highlights read as wet plastic, most
    // on dark skin); the cheeks keep only the broad sheen; the lips are moist, broken by their
    // furrows; brow hair has none.
    float ndv = max(dot(n, v), 1e-4);
    float oil = detail.b * (1.0 - 0.35 * u_age) * mix(0.8, 1.15, patches) * (1.0 - lips);
    float film = smoothstep(0.75, 1.05, oil);
    film *= film > 0.0 ? oil_pools(skin_uv) : 1.0;   // pooled, not an even glaze (skin_light.glsl)
    // Moist, but the film is broken by the furrows and by the lips' fine mottle: a continuous
    // glossy band along the lip read as rubber.
    // The film beads and dries in patches a millimetre or two across (moist), so the narrow
    // highlight breaks into strokes between the furrows rather than one band.
    // (Off the lips, nearly all pixels, the noise is skipped.)
    float moist = lips > 0.0 ? smoothstep(0.3, 0.75, value_noise(skin_uv * vec2(260.0, 520.0) + 31.0, 0)) : 0.0;
    float wet = max(lips * (1.0 - lip_line) * (1.0 - lip_line) * (1.0 - fissure) * (0.25 + 0.75 * moist) * (0.55 + 0.45 * blotch), mucosa);
    // Lobe weights (broad, tight); the fill is too weak to show: key and rim only.
    SkinLobes lobes = skin_lobes(oil, film, lips, wet, blotch, patches);
    vec2 weight = lobes.weight;
    weight.x *= 1.0 + PORE_SKIN_SHEEN * smoothstep(PORE_SKIN_RANGE.x, PORE_SKIN_RANGE.y, tone.b) * (1.0 - lobes.lip);
    vec2 roughness = lobes.roughness;
    // The key's lobes spread by its softbox's size (softbox_roughness), except on the wet lips: their
    // film's beads and furrows curve within a millimetre or two and mirror the box as small glints.
    vec2 key_roughness = mix(softbox_roughness(roughness, KEY_SOFTBOX_HALF_ANGLE), roughness, lobes.lip);
    vec3 spec = dot(skin_specular(sheen_n, u_key_dir, v, ndv, key_roughness), weight) * u_key_col * key_shadow
              + dot(skin_specular(sheen_n, u_rim_dir, v, ndv, roughness), weight) * u_rim_col;
    // (Times pi: the diffuse term here is albedo times N.L, without the Lambert 1/pi.)
    spec *= PI * (1.0 - hair) * (0.85 + 0.3 * grain) * spec_break
          * max(1.0 + PORE_SHEEN * (0.6 + tone.b) * (1.0 - lips) * pores, 0.0);
    // The same surface mirrors the room (sky and ground) too, faintly and evenly, F0 of it: a
    // thin veil of white over the skin's colour between the highlights (without it, the T-zone's
    // sheen pooled into sharp highlights left the skin between them a more saturated paint).
    spec += schlick(SKIN_F0, ndv) * (weight.x + weight.y) * hemisphere(reflect(-v, bumped)) * (1.0 - hair) * spec_break;
    // The mucosa's film of saliva mirrors the lights in a thin bright line where the lip's
    // inner edge turns toward them. (A branch: llvmpipe skips it for the blocks of pixels
    // away from the lips, nearly all of them.)
    if (mucosa > 0.0) {
        spec += mucosa * MUCOSA_SHINE * (blinn(n, u_key_dir, v, 50.0) * u_key_col * key_shadow + blinn(n, u_rim_dir, v, 50.0) * u_rim_col);
    }
    // Peach fuzz: the fine vellus hair on the cheeks and forehead scatters a faint, soft sheen
    // where the skin turns away from the eye (toward the face's outline), never a highlight.
    float graze = 1.0 - ndv;
    graze *= graze;
    vec3 fuzz_light = u_key_col * key_shadow * max(dot(n_smooth, u_key_dir), 0.0) + u_rim_col * max(dot(n_smooth, u_rim_dir), 0.0)
                    + hemisphere(n_smooth);
    spec += PEACH_FUZZ * graze * graze * fuzz_light * mix(vec3(1.0), albedo, 0.5) * (1.0 - lips) * (1.0 - hair);
#ifdef USE_WRINKLE
    // Light reaching a valley's floor has passed through the skin around it: a little redder.
    vec3 crevice_tint = mix(vec3(1.0), vec3(1.0, 0.94, 0.92), 0.4 * fold.fold_amount * fold.fold_amount * fold.valley * scatter);
#else
    vec3 crevice_tint = vec3(1.0);
#endif
    radiance = (diffuse + spec * contact) * cavity * crevice_tint;
#endif

#ifdef REGION_EYEBALL
    vec3 e = normalize(v_eye);
    float r = length(e.xy);
    float front = step(0.0, e.z);
    float aa = max(fwidth(r), 1e-4);
    bool on_a = distance(v_pos, u_eye_a) < distance(v_pos, u_eye_b);
    mat3 eye_rot = on_a ? u_eye_rot_a : u_eye_rot_b;
    // The cornea bulges over the iris as a sphere of 1.33 iris radii (7.8 mm over an
    // 11.7-mm iris). The view ray refracts through it and meets the iris deeper in: the
    // iris (and pupil) is drawn where the refracted ray lands, so it shifts with the view
    // as a real one does (parallax), while the limbus stays on the eyeball.
    vec2 bulge = e.xy / CORNEA_RADIUS;
    vec3 corneal = vec3(bulge, sqrt(max(1.0 - dot(bulge, bulge), 0.0)));
    vec3 into = refract(-(transpose(eye_rot) * v), corneal, 1.0 / CORNEA_INDEX);
    float chamber = ANTERIOR_CHAMBER * max(1.0 - r * r / (IRIS_RADIUS * IRIS_RADIUS), 0.0);
    vec2 seen = e.xy + into.xy * chamber / max(-into.z, 0.25);
    float ri = length(seen);
    float aai = max(fwidth(ri), 1e-4);
    float pupil_radius = mix(PUPIL_RADIUS.x, PUPIL_RADIUS.y, u_age);
    float pupil_mask = front * (1.0 - smoothstep(pupil_radius - aai, pupil_radius + aai, ri));
    float t = clamp((ri - pupil_radius) / (IRIS_RADIUS - pupil_radius), 0.0, 1.0);
    float angle = atan(seen.y, seen.x);
    float turns = (angle / (2.0 * PI) + 0.5) * float(IRIS_FIBRES);
    // Each iris its own pattern: the other eye's frame is a reflection, so one noise drew the
    // two irises as mirror twins, a cast pair (issue 13: "glassy, doll eyes"). Its noise is
    // read elsewhere along the radius-like axis (which keeps the angular wrap seamless).
    float iris_seed = on_a ? 0.0 : 23.0;
    // Stroma: fine radial fibres (long along the radius, narrow around it), coarser bundles,
    // faded to their mean where they would be finer than a pixel (small images stay calm).
    float fibre_detail = clamp(1.6 - 0.6 * fwidth(turns), 0.0, 1.0);
    // (The fibres wander: evenly spaced straight spokes read as a wheel of glass. At 1.6 cells
    // across the iris they still ran as straight spokes: now 3, bending twice as often.)
    float wander = 3.0 * (value_noise(vec2(turns * 0.125, t * 8.0 + 21.0 + iris_seed), IRIS_FIBRES / 8) - 0.5);
    // The coarse bundles (a quarter as many around) fade only where they in turn would be finer
    // than a pixel: at 448² the fine fibres are gone, and a disc of one even colour read as a
    // glass or doll's eye (issue 13); a photographed iris there still shows its streaks.
    // (Where the fibres show, the bundles keep their old share, 0.15; where the fibres have
    // faded, twice that. The mean stays 0.5.)
    float fibre = 0.55 * value_noise(vec2(turns + wander, t * 3.0 + iris_seed), IRIS_FIBRES)
                + 0.3 * value_noise(vec2(turns * 2.0 + 2.0 * wander, t * 1.5 + 3.0 + iris_seed), IRIS_FIBRES * 2);
    fibre = mix(0.425, fibre, fibre_detail);
    float bundle_detail = clamp(1.6 - 0.6 * fwidth(turns * 0.25), 0.0, 1.0);
    float bundle = mix(0.5, value_noise(vec2(turns * 0.25, t * 6.0 + 11.0 + iris_seed), IRIS_FIBRES / 4), bundle_detail);
    fibre += 0.075 + mix(IRIS_BUNDLES_ALONE, 0.15, fibre_detail) * (bundle - 0.5);
    // The collarette, a third of the way out, is a wavy ridge (it zigzags around the iris):
    // inside it the pupillary zone is darker and warmer, outside it the ciliary zone is
    // broken by darker crypts; a dark ruff rims the pupil and a dark limbal ring the iris.
    float wave = COLLARETTE_WAVE * (value_noise(vec2(turns * 0.33, 0.5 + iris_seed), IRIS_FIBRES / 3) - 0.5);
    float collar_t = t - COLLARETTE - wave;
    float inner = 1.0 - smoothstep(-0.03, 0.03, collar_t);
    float ridge = exp(-pow(collar_t / 0.035, 2.0));
    float crypt = smoothstep(0.68, 0.9, value_noise(vec2(turns * 0.5, t * 5.0 + 5.0 + iris_seed), IRIS_FIBRES / 2))
                * smoothstep(0.0, 0.1, collar_t) * (1.0 - smoothstep(0.7, 0.9, t)) * fibre_detail;
    // Less saturated than the base colour: a real iris is a greyish stroma over its pigment,
    // and a clean saturated colour read as a glass or doll's eye (issue: "glassy eyes",
    // most of all blue ones). The stroma's radial fibres are paler and greyer than the
    // hollows between them, where the pigment shows.
    float iris_grey = dot(u_iris, vec3(0.3, 0.55, 0.15));
    // (Dark brown irises keep more of their hue: their melanin is in the stroma itself, and
    // greyed they read as black discs, as a doll's eyes.)
    vec3 base_iris = mix(u_iris, vec3(iris_grey), mix(0.3, 0.62, smoothstep(0.03, 0.12, iris_grey)));
    vec3 iris = base_iris * (0.42 + 1.05 * fibre);
    iris = mix(iris, vec3(iris_grey) * vec3(1.05, 1.0, 0.92) * (0.35 + 1.1 * fibre), 0.35 * smoothstep(0.45, 0.8, fibre) * fibre_detail);
    iris *= mix(vec3(1.0), vec3(0.72, 0.64, 0.52), PUPILLARY_ZONE * inner);   // darker, warmer pupillary zone
    iris *= 1.0 - 0.3 * ridge * fibre_detail;                          // the collarette's dark fold
    iris *= 1.0 - 0.3 * crypt;
    // Broad sectors, a few around the iris, lighter or darker and a little warmer where darker
    // (pigment lies unevenly in the stroma): they outlast the fibres at 448-512², where an iris
    // of even spokes round a wheel read as glass.
    float sector = value_noise(vec2(turns / 12.0, 2.0 * t + 40.0 + iris_seed), IRIS_FIBRES / 12) - 0.5;
    iris *= 1.0 + IRIS_SECTORS * 2.0 * sector * vec3(0.9, 1.0, 1.15);
    iris *= mix(0.45, 1.0, smoothstep(0.0, 0.08, t));                 // pupillary ruff
    iris *= mix(1.0, LIMBAL_RING, smoothstep(1.0 - LIMBUS_WIDTH, 1.0, t));    // limbal ring
    // The cornea gathers the key's light from above onto the iris's lower part (the limbal
    // caustic): in photographs the iris glows below its pupil and darkens under the upper lid,
    // where a flat, evenly lit disc read as glass.
    iris *= 1.0 + IRIS_CAUSTIC * smoothstep(0.0, 0.9, -seen.y / IRIS_RADIUS) * smoothstep(0.25, 0.75, t);
    // The pupil is not ink: the lens behind it returns a little light (and the cornea in
    // front reflects the room, below).
    vec3 pupil = max(u_pupil, vec3(0.006, 0.0055, 0.0055)) * mix(1.3, 0.8, smoothstep(0.0, 0.8, ri / pupil_radius));
    iris = mix(iris, pupil, pupil_mask);
    // The socket's frame: hx across the eye toward the nose (the other eye), hy up, in
    // eyeball radii from this eye's centre.
    vec3 centre = on_a ? u_eye_a : u_eye_b;
    vec3 to_nose = (on_a ? u_eye_b : u_eye_a) - centre;
    to_nose = length(to_nose) > 1e-6 ? normalize(to_nose) : vec3(-sign(v_pos.x), 0.0, 0.0);
    vec3 socket = (v_pos - centre) / u_eye_radius;
    float hx = dot(socket, to_nose);
    float hy = socket.y;
    float theta = acos(clamp(e.z, -1.0, 1.0));
    // Off-white sclera (never paper white): a touch warmer and pinker toward the corners
    // (conjunctival vessels, strongest nasally and temporally), with faint, thin vessels
    // that run from the corners toward the iris and fade out before they reach it.
    float corner = smoothstep(0.4, 0.8, theta) * (0.55 + 0.45 * abs(cos(angle)));
    vec2 vp = vec2(angle * 7.0, theta * 2.5);
    float vessel_n = value_noise(vp, 0) + 0.5 * value_noise(vp * 2.3 + 7.0, 0);
    float vessel_w = 0.05 + fwidth(vessel_n);
    float vessels = (1.0 - smoothstep(0.0, vessel_w, abs(vessel_n - 0.75))) * 0.05 / vessel_w
                  * smoothstep(0.45, 0.85, theta) * (0.5 + 0.5 * abs(cos(angle)));
    vec3 sclera = u_sclera * vec3(0.88, 0.85, 0.81)
                * mix(vec3(1.0), vec3(0.9, 0.7, 0.63), corner)
                * mix(vec3(1.0), vec3(0.95, 0.55, 0.5), clamp(1.1 * vessels, 0.0, 0.6));
    // Nor is it porcelain: faint patches a few millimetres across, warmer or cooler where the
    // conjunctiva is thicker or its vessels closer (one even white read as a glass eye).
    float mottle = value_noise(e.xy * 6.0 + 31.0, 0) + 0.5 * value_noise(e.xy * 13.0 + 5.0, 0) - 0.75;
    sclera *= 1.0 + SCLERA_MOTTLE * mottle * vec3(0.85, 1.0, 1.15);
    // Caruncle and plica: a pink, fleshy, wet mound fills the inner corner (e.x toward the
    // nose: -x for the eye on the +x side of the head), a darker fold (the plica) between
    // it and the sclera.
    float nasal = smoothstep(CARUNCLE.x, CARUNCLE.y, hx);
    float plica = exp(-pow((hx - CARUNCLE.x) / 0.03, 2.0));
    sclera *= 1.0 - 0.25 * plica;
    sclera = mix(sclera, u_sclera * vec3(0.78, 0.42, 0.40) * (0.85 + 0.3 * value_noise(e.xy * 60.0, 0)), nasal);
    // The limbus blends softly into the sclera as a greyish ring (no cut-out edge).
    float limbal = front * exp(-pow((r - IRIS_RADIUS) / 0.045, 2.0));
    sclera *= 1.0 - 0.25 * limbal;
    float iris_soft = front * (1.0 - smoothstep(IRIS_RADIUS - aa - 0.015, IRIS_RADIUS + aa, r));
    sclera *= orbit_shade(hy);   // (the white only: the lids hide the iris's top but where 5 bares it)
    iris *= socket_top_shade(hy);   // (the iris only: the white above it keeps 5's sign, orbit_shade)
    // The limbus is a band, not a line: the iris's dark rim fades into the white over ~0.5 mm
    // (the cornea's edge is clouded), where a cut-out disc read as a doll's inset eye. (Mostly
    // inward: the white that 5 bares above the iris stays white.)
    float limbus_blend = front * (1.0 - smoothstep(IRIS_RADIUS - 0.022, IRIS_RADIUS + 0.01 + aa, r));
    vec3 albedo = mix(sclera, iris, max(limbus_blend, 0.6 * iris_soft));
#ifdef USE_LIDS
    // Along the lids (v_lids: degrees of arc from each margin; ~1.7 px per degree at 1024²):
    // the lower lid's wet inner rim, its margin rolled in against the eyeball, shows as a
    // thin pink band, with the tear meniscus's bright line just above it; under the upper
    // lid the lash line and the lid itself shade the eyeball deeply (below).
    float px = max(fwidth(v_lids.y), 1e-3);
    float rim = (1.0 - smoothstep(WET_RIM - 0.5 * px, WET_RIM + 0.5 * px, v_lids.y))
              * smoothstep(-3.0, -2.0, v_lids.y);   // (the lid hides what lies further below)
    // (Both fade out toward the canthi, where the lower margin turns up steeply and the
    // caruncle takes over.)
    float along_lower = (1.0 - smoothstep(0.45, 0.62, abs(hx))) * (1.0 - smoothstep(-0.1, 0.1, hy));
    float wet_rim = rim * along_lower;
    albedo = mix(albedo, WET_RIM_COLOR, wet_rim);
    float tear_w = max(TEAR_WIDTH, px);
    float tear = exp(-pow((v_lids.y - WET_RIM - 0.5 * TEAR_WIDTH) / tear_w, 2.0)) * TEAR_WIDTH / tear_w * along_lower;
    float lash_shadow = 1.0 - UPPER_SHADOW.x * exp(-max(v_lids.x, 0.0) / UPPER_SHADOW.y);
    float lid_cast = 1.0 - UPPER_LID_CAST.x * exp(-max(v_lids.x, 0.0) / UPPER_LID_CAST.y);
    // The lids' broad shade: the thick upper fold stands off the eyeball and hides much of
    // the light above it; the lower lid a little of the light below.
    occ *= (1.0 - UPPER_LID_SHADE.x * exp(-max(v_lids.x, 0.0) / UPPER_LID_SHADE.y))
         * (1.0 - LOWER_LID_SHADE.x * exp(-max(v_lids.y, 0.0) / LOWER_LID_SHADE.y));
#else
    float rim = 0.0, wet_rim = 0.0, tear = 0.0, lash_shadow = 1.0, lid_cast = 1.0;
#endif
    // The eyeball sits in the lids' shade. The thick upper lid and its lashes shadow a band
    // under its margin and the lower lid a little above its own: that shade follows the lids
    // in every frame (v_lids, above), so 5 bares lit sclera and 43 closes the shadow away.
    // Here only what the lids cannot say: the canthi shade
    // the corners, and light falls off over the eyeball's curve toward the orbit (socket
    // frame: at rest about hy in [-0.2, 0.2] and hx in [-0.65, 0.65] show between the
    // lids). The socket around it hides much of the sky: the whole eyeball
    // takes less ambient than the skin.
    // (0.7 left the sclera beside the iris a grey ring well below the skin's brightness: glass.)
    float lid_shade = 0.85 * (1.0 - 0.15 * smoothstep(-0.05, 0.3, hy)) * (1.0 - 0.5 * smoothstep(0.32, 0.68, abs(hx)))
                    * lash_shadow;
    vec3 diffuse = diffuse_light(n, vec3(0.15), occ) * albedo * lid_shade * lid_cast;
    // Wet surface. The cornea bulges over the iris as a sphere of 1.33 iris radii (7.8 mm
    // over an 11.7-mm iris), so its normal tilts faster than the eyeball's: the catch-light
    // sits on the iris, not beside it (eye_rot turns the corneal normal with the eye). It
    // mirrors what lights the face: the key is a softbox, so its catch-light is one small,
    // soft-edged rounded rectangle, not a pin-point nor a glossy blob; the fill's is faint,
    // and the room's faint glow lies over the whole cornea (the pupil is never ink black).
    float cornea = front * (1.0 - smoothstep(IRIS_RADIUS - 0.02, IRIS_RADIUS + 0.02, r));
    vec3 nc = normalize(mix(n, eye_rot * corneal, cornea));
    vec3 refl = reflect(-v, nc);
    float ndv = max(dot(nc, v), 0.0);
    float fres = schlick(0.025, ndv) / 0.025;
    vec3 room = mix(u_ground_col, u_sky_col, 0.5 + 0.5 * refl.y) * ROOM_REFLECTION;
    // The boxes are mirrored by the cornea alone: the normals blended across the limbus swept
    // through the key's reflection and drew a second highlight on its rim, beside the iris.
    vec3 refl_cornea = reflect(-v, eye_rot * corneal);
    vec3 boxes = (softbox(refl_cornea, catch_light_direction(u_key_dir), SOFTBOX) * u_key_col * KEY_REFLECTION
                  + softbox(refl_cornea, u_fill_dir, FILL_BOX) * u_fill_col * FILL_REFLECTION) * cornea;
    vec3 spec = (boxes + room * mix(0.45, 1.0, cornea)) * fres;
    // The sclera and the lid's wet rim are wet too but less smooth (a broad sheen), and the
    // tear meniscus catches a thin bright line of the key.
    spec += specular_light(n, v, 40.0) * 0.03 + tear * u_key_col * TEAR_SHINE;
    spec *= mix(0.5, 1.0, lash_shadow) * mix(0.4, 1.0, lid_shade / 0.85);
    // The lower lid's wet margin faces up and out of the socket: it takes the room's ambient
    // light that the eyeball under the lids does not, and its film mirrors the room as a
    // soft sheen, so it reads as a moist band, not a painted pink line.
    spec += wet_rim * mix(u_ground_col, u_sky_col, 0.5 + 0.5 * refl.y) * WET_RIM_SHEEN;
    // Its margin is a ledge that faces up toward the key: lit as one, not in the eyeball's
    // shade (there it drew a dark line under the eye, an outline round a doll's eye).
    vec3 rim_n = normalize(n + vec3(0.0, 1.5, 0.0));
    diffuse = mix(diffuse, diffuse_light(rim_n, vec3(0.2, 0.1, 0.1), occ) * WET_RIM_COLOR, 0.5 * wet_rim);
    radiance = diffuse + spec * occ;
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
    // The biting edge's outline (incisal_notch): cutting it out of the band (discard) gives
    // each tooth its own silhouette and the dark embrasures between.
    float tooth_id = float(kind) + 7.0 * step(0.0, v_uv.x) + 14.0 * lower;
    float notch = incisal_notch(kind, side, lower) + (kind <= 1 ? incisal_unevenness(tooth_id, w) * mix(1.0, 0.5, lower) : 0.0);
    // A band without coordinates (all (0, 0): constant, so no derivative) stays whole.
    bool shaped = fwidth(v_uv.x) + fwidth(v_uv.y) > 0.0;
    if (shaped && max(h, lingual) < notch) discard;
    // Each crown is convex: it turns away from the light toward its neighbours, and where two
    // touch they leave a soft shadow (embrasure_shade).
    float gap_aa = fwidth(arc);
    float to_gap = min(arc - b0, b1 - arc);
    float convex = 1.0 + CROWN_ROUNDING * (1.0 / 3.0 - side * side);
    float gap = shaped ? 1.0 - embrasure_shade(to_gap, gap_aa, h, lower) : 1.0;
    // Scalloped gum line, arched rootward over each crown (crowns ~10 mm of the band's 16),
    // papillae reaching toward the biting edge between crowns. A smile rarely shows it;
    // where it shows it is pink, lit like the teeth (no dark band under the lip).
    // GUM_LINE: (papillae, zenith) in band units (~16 mm): the zenith ~10.5 mm above the upper
    // central's edge, ~9 mm above the lower's, as on natural crowns. (At 0.82, ~13 mm, the crowns
    // were too long for any smile to reach the gum: issue 13, "no gums in broad smiles".)
    float gum_edge = mix(GUM_LINE.x, GUM_LINE.z, lower) + mix(GUM_LINE.y - GUM_LINE.x, GUM_LINE.w - GUM_LINE.z, lower) * sin(PI * w);
    // (Labial side only: the lingual gum lies deep in the arch's shade, and drawn pink it
    // showed as red dots between the lower crowns when 16 bared them.)
    float gum = smoothstep(gum_edge - 0.025, gum_edge + 0.025, h);
    // Ivory enamel, never one flat white: each crown has its own shade (canines a little
    // yellower), mottled in faint vertical streaks; warmer toward the neck
    // where dentin shows through; at the biting edge the enamel holds no dentin and lets the
    // light through: a translucent blue-grey band (~1.5 mm) under a thin bright rim (the
    // incisal halo, light caught in the edge), as in photographs of teeth.
    // (Per tooth: its value, its yellowing and how translucent its edge is, each from its own
    // hash; TOOTH_SHADE_SPREAD. Within 0.92-1.04 and one hue the row read as a uniform strip.)
    float vary = hash2(ivec2(int(tooth_id), 29));
    float yellowing = hash2(ivec2(int(tooth_id), 41));
    vec3 front = vec3(float(kind == 0), float(kind == 1), float(kind == 2));   // which front tooth, if any
    float back = 1.0 - dot(front, vec3(1.0));   // 1 on the other teeth, which keep factor 1
    float kind_value = dot(front, TOOTH_KIND_VALUE) + back;
    vec3 enamel = u_albedo * (1.0 + TOOTH_SHADE_SPREAD.x * (vary - 0.75)) * kind_value
                * mix(vec3(1.0), TOOTH_YELLOW, TOOTH_SHADE_SPREAD.y * yellowing + dot(front, TOOTH_KIND_YELLOW));
    float streak = value_noise(vec2(v_uv.x * 140.0, max(h, lingual) * 5.0), 0);
    enamel *= 0.96 + 0.08 * mix(0.5, streak, clamp(1.5 - 20.0 * fwidth(v_uv.x), 0.0, 1.0));
    float edge_h = max(h, lingual) - notch;                 // band units above the edge
    float incisal = (1.0 - smoothstep(0.025, 0.1, edge_h)) * (kind <= 2 ? 1.0 : 0.5) * mix(1.0, 0.6, lower);
    float translucent = INCISAL_TRANSLUCENCY * (0.6 + 0.8 * hash2(ivec2(int(tooth_id), 53)))
                      * (dot(front, TOOTH_KIND_TRANSLUCENCY) + back);
    enamel = mix(enamel, dot(u_albedo, vec3(0.33)) * vec3(0.86, 0.92, 1.0), translucent * incisal);
    float halo_w = max(0.012, fwidth(edge_h));
    enamel *= 1.0 + 0.22 * exp(-edge_h * edge_h / (halo_w * halo_w)) * (0.012 / halo_w) * float(shaped);
    enamel *= mix(vec3(1.0), TOOTH_CERVICAL, smoothstep(0.25, gum_edge, h));   // dentin at the neck
    vec3 gums = vec3(0.62, 0.27, 0.28) * (0.92 + 0.16 * value_noise(v_uv * vec2(60.0, 8.0), 0));
    vec3 albedo = mix(enamel * gap * convex, gums, gum);
    // The lingual slope is enamel only near the biting edge (the crowns' inner faces, ~4 mm);
    // beyond lies the lingual gum and the mouth's floor, wet and in the arch's shade. Drawn as
    // enamel it showed as a pale grey wall inside the far side of the arch in three-quarter views
    // and as grey slabs at the corners when the jaw dropped. Dark enough that between the lower
    // crowns it reads as shade, not as red dots.
    float lingual_gum = smoothstep(0.25, 0.5, lingual);
    albedo = mix(albedo, gums * 0.55, lingual_gum);
    // Each crown bulges (~1 mm over its width): its normal turns across it (a surface
    // gradient from screen derivatives, as on the skin), so the key lays a soft highlight
    // down each crown and its flanks turn into shade: separate teeth, not a flat strip.
    // (A bulge of (b1 - b0) / 8 (~1 mm) times 1 - (2w - 1)^2 across the crown: slope -0.5 (2w - 1).)
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 along = sign(dot(dpdx, cross(dpdy, n))) * (dFdx(arc) * cross(dpdy, n) + dFdy(arc) * cross(n, dpdx));
    n = crown_normal(n, along, -0.5 * (2.0 * w - 1.0) * (1.0 - gum) * float(shaped));
    // Light inside the mouth falls off with depth: the front teeth catch it, the back ones sit
    // in the shadow of the cheeks (the dark buccal corridor). The upper lip casts a soft
    // contact shadow just under its edge: v_occlusion is the fragment's height (dm) below
    // that edge in this frame, less toward the mouth's corners, where the lips and cheeks
    // shade the teeth (facsim.head.mouth.mouth_light; 1 when nobody passes it). The
    // lower row stands back under the upper teeth and lip and faces up into the mouth:
    // darker, and mostly hidden.
    // (The lower row's back teeth sit lower in the cheeks' shade: its corridor starts nearer
    // the front, or a stretched mouth (20+26) showed them as pale slabs in its corners.)
    float depth_shade = mix(1.0, 0.09, smoothstep(mix(0.12, 0.08, lower), mix(0.36, 0.28, lower), arc));
    float slit_light = mix(CLOSED_LIPS_DARK, 1.0, smoothstep(-1.3, -0.7, v_occlusion));
    float lip_shadow = mix(LIP_SHADOW_FLOOR, 1.0, smoothstep(-0.002, 0.022, v_occlusion)) * slit_light;
    float row_light = mix(1.0, 0.55, lower);
    // The inside of the arch faces the tongue and throat: it only catches light scattered in.
    float mouth_shade = depth_shade * lip_shadow * row_light * mix(1.0, 0.12, smoothstep(0.0, 0.1, lingual))
                      * mix(1.0, 0.5, lingual_gum);
    float wet = specular_light(n, v, 120.0).r * 0.35 + specular_light(n, v, 30.0).r * 0.05;
    vec3 spec = vec3(wet) * (1.0 - 0.6 * gum) * schlick(0.05, max(dot(n, v), 0.0)) * 3.0;
    // (Each crown's its own: off its middle by up to a tenth of its width, and stronger or weaker.)
    float sheen_across = (w - 0.5 - 0.2 * (vary - 0.5)) / ENAMEL_SHEEN_WIDTH;
    spec += ENAMEL_SHEEN * (0.7 + 0.6 * yellowing) * exp(-sheen_across * sheen_across) * pow(max(dot(n, v), 0.0), 4.0)
          * (1.0 - smoothstep(0.1, gum_edge, h)) * mix(1.0, LOWER_ROW_SHEEN, lower) * float(shaped);
    // Enamel scatters light inside the tooth: a little of its own brightness beyond the lighting.
    radiance = ((diffuse_light(n, vec3(0.3, 0.25, 0.2), TEETH_AMBIENT) * TEETH_DIFFUSE + ENAMEL_GLOW) * albedo * mix(INSIDE_WARMTH, vec3(1.0), gum)
                + spec) * mouth_shade;
    // What light reaches the back teeth has bounced off the cheeks' red lining: warm, not grey.
    // So does what reaches the inside of the arch.
    radiance *= mix(vec3(1.0, 0.6, 0.5), vec3(1.0), depth_shade * (1.0 - 0.8 * smoothstep(0.0, 0.3, lingual)));
    radiance += DEEP_TEETH_LIGHT * DEEP_TEETH_BOUNCE * albedo * (1.0 - mouth_shade) * slit_light;
    radiance *= mix(vec3(1.0), LOWER_ROW_BOUNCE, lower);
#endif

#ifdef REGION_TONGUE
    // v_uv = (across -1..1, along 0 at the tip .. 1 at the root), facsim.head.mouth.tongue_coordinates.
    float across = v_uv.x, along = clamp(v_uv.y, 0.0, 1.0);
    // hm08's tongue is coarse (~1 cm facets): its interpolated normals drew the wet sheen as
    // streaks along the triangles' edges and the diffuse light in facets (issue 13). A tongue
    // is a smooth, soft dome: it is shaded with its normal averaged over its neighbours.
    vec3 n_smooth = normalize(gl_FrontFacing ? v_scatter_normal : -v_scatter_normal);
    n = normalize(mix(n, n_smooth, TONGUE_SMOOTHING));
    // Median groove, papillae as fine mottling, a paler coat toward the middle.
    float groove = 1.0 - 0.35 * exp(-across * across / 0.012) * smoothstep(0.05, 0.3, along) * (1.0 - smoothstep(0.35, 0.6, along));
    // (~1-mm cells: where they are finer than a pixel they fade to their mean, or their
    // aliased noise drew the sheen as streaks and specks.)
    vec2 papillae_uv = v_uv * vec2(40.0, 60.0);
    float papillae_detail = clamp(1.5 - max(fwidth(papillae_uv.x), fwidth(papillae_uv.y)), 0.0, 1.0);
    float papillae = 0.85 + 0.3 * mix(0.5, value_noise(papillae_uv, 0), papillae_detail);
    vec3 albedo = u_albedo * vec3(0.88, 0.72, 0.74) * papillae * groove;
    // The tongue lies in the shadow of the lips and upper teeth: dim at the tip, dark at its
    // sides against the teeth, the light falling off with depth toward the root
    // (tongue_depth_light). How much light the parted lips let in arrives in occ
    // (facsim.head.mouth.mouth_light).
    vec3 mouth_shade = tongue_depth_light(along) * mix(1.0, 0.5, smoothstep(0.4, 1.0, abs(across)))
                     * mix(0.1, 1.0, occ);
    // Moist: a soft sheen broken by the papillae, and a tighter glint on the film of saliva.
    // (A broad lobe, shininess 40 at 0.12, laid one smooth highlight over the whole dome: "the
    // tongue has a plastic sheen". The papillae make the surface velvety: little broad sheen,
    // the glints where the film pools between them.)
    vec3 spec = specular_light(n, v, 60.0) * 0.06 * papillae + specular_light(n, v, 120.0) * 0.3 * smoothstep(0.8, 1.1, papillae);
    // The film mirrors the key through the opening wherever the tongue's front faces it: the
    // sheen is dimmed by how far back it lies and by the light the lips let in, not by the
    // shade that scattered light falls into (there it was lost, a matte tongue).
    float sheen_light = mix(0.7, 0.04, smoothstep(0.0, 0.45, along)) * mix(0.1, 1.0, occ);
    radiance = diffuse_light(n, vec3(0.3, 0.15, 0.1), 1.0) * 0.8 * albedo * mouth_shade + spec * sheen_light;
#endif

#ifdef REGION_MOUTH_INTERIOR
    // Mostly hidden and in the mouth's own shadow: dim, dark red, a little wet; falls off with
    // depth behind the lips (Face passes facsim.head.mouth.mouth_depth_visibility in occ) to
    // a warm, dull dark (light scattered through cheeks and lips), never black and never a
    // saturated red (seen through the gaps between the teeth, red read as braces' bands).
    // Just inside the lips the lining is their mucosa going on, lit through the opening as
    // the lips part (mouth_light lifts occ there): the lips' red and wet film, not the dark.
    float lip_side = smoothstep(0.6, 0.9, occ);
    // The palate faces down, away from what light the opening lets in, in the shade of the
    // upper teeth and lip: lit only by what the tongue bounces up (ROOF_LIGHT). Lit as the
    // floor, it was a flat red shelf under the upper teeth.
    float mouth_shade = occ * occ * mix(ROOF_LIGHT, 1.0, max(smoothstep(-0.7, 0.0, n.y), lip_side));
    vec3 spec = specular_light(n, v, 30.0) * mix(0.04, 0.3, lip_side);
    vec3 deep = cavity_deep_colour(u_albedo, occ);
    vec3 albedo = mix(u_albedo * 0.45, mucosa_colour(u_lips) * 0.8, lip_side);
    radiance = (diffuse_light(n, vec3(0.3, 0.1, 0.1), 1.0) * mix(DEEP_BOUNCE, vec3(1.0), lip_side) * albedo + spec) * mouth_shade
             + deep * (1.0 - mouth_shade);
    // The back wall's shape: the throat's dark opening, the uvula hanging in it, the arch's rim.
    vec3 throat = throat_shape(v_eye);
    float uvula_round = 1.0 - 0.6 * pow(clamp(abs(v_eye.x) / UVULA.y, 0.0, 1.0), 2.0);
    radiance *= mix(1.0, THROAT_DARK, throat.x) * mix(1.0, UVULA_LIGHT * uvula_round, throat.y) * (1.0 + 0.3 * throat.z);
#endif

#ifdef REGION_GARMENT
    // Cloth: matte (no specular highlight), a soft wrap of light past the terminator, a faint
    // sheen at grazing angles (fibres standing off the surface catch the light) and a fine knit
    // grain, fading to its mean where it would be finer than a pixel.
    // Soft folds under the collar at the front: a few shallow ridges running down from the
    // band (FOLD_SPACING dm apart along the neckline, FOLD_DEPTH dm deep, fading over
    // FOLD_LENGTH band widths below it and away from the front), shaded by bumping the normal
    // along the surface gradient of their height (screen-space derivatives, no tangents needed).
    float fold_along = v_uv.x / FOLD_SPACING;
    float fold_env = smoothstep(0.9, 1.6, v_uv.y) * (1.0 - smoothstep(1.6, FOLD_LENGTH, v_uv.y))
                   * exp(-v_uv.x * v_uv.x / (FOLD_REACH * FOLD_REACH));
    float fold_h = FOLD_DEPTH * fold_env * (0.5 - 0.5 * cos(2.0 * PI * fold_along));
    vec3 dpdx = dFdx(v_pos), dpdy = dFdy(v_pos);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    vec3 surface_grad = sign(det) * (dFdx(fold_h) * r1 + dFdy(fold_h) * r2);
    n = normalize(abs(det) * n - surface_grad);
    vec2 knit_uv = vec2(v_pos.x * 90.0, v_pos.y * 60.0);
    float knit = mix(0.5, value_noise(knit_uv, 0), clamp(2.0 - 1.5 * max(fwidth(knit_uv.x), fwidth(knit_uv.y)), 0.0, 1.0));
    vec3 cloth = u_albedo * (0.94 + 0.12 * knit);
    // The collar: a ribbed band along the neckline (v_uv: arc length around the neck in dm,
    // distance from the neckline in band widths), its ribs ~3 mm apart, a shade darker and
    // denser than the body of the garment, its edge in the rim's shade.
    float band = 1.0 - smoothstep(0.8, 1.0, v_uv.y);
    float rib_x = v_uv.x * 33.0;
    float rib = mix(0.5, 0.5 + 0.5 * cos(2.0 * PI * rib_x), clamp(2.0 - 2.0 * fwidth(rib_x), 0.0, 1.0));
    cloth *= mix(1.0, 0.86 + 0.1 * rib, band);
    float grazing = pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 3.0);
    radiance = diffuse_light(n, vec3(0.25), occ) * cloth * (1.0 + 0.25 * grazing);
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
