// Proxy fragment shader: hair, eyebrow and eyelash cards cut out by their texture's alpha.
// Variants (#defines from facsim/render/proxies.py): PASS_OPAQUE (alpha-tested, writes depth) or
// PASS_BLEND (the soft fringe, blended back to front); KIND_HAIR, KIND_EYEBROWS, KIND_EYELASHES,
// KIND_SCALP, KIND_WISPS; COILY for coily hair (its curls cost llvmpipe time even where a uniform skips them).

#include "common.glsl"
#include "shadow.glsl"

in vec3 v_pos;
in vec3 v_normal;
in vec3 v_tangent;
in float v_depth;
in float v_edge;
in vec2 v_uv;
in float v_cover;
in vec3 v_rest;
in vec3 v_rest_tangent;

uniform sampler2D u_texture;  // R: strand brightness (0.5 = mean), GB: strand direction in UV, A: coverage
uniform vec3 u_color;         // linear RGB
uniform float u_along_v;      // 1: the texture's strands run along v everywhere (else: tex.gb says where)
uniform float u_sheen;        // strand highlight strength (1 straight hair, less for coily)
uniform float u_density;      // brows and lashes: how much of the skin their hairs cover
uniform float u_coil;         // hair: 0 straight ... 1 coily
uniform vec3 u_pigment;       // greying hair: its pigmented strands' colour (linear RGB) ...
uniform vec3 u_white;         // ... its white strands' ...
uniform float u_grey;         // ... and the fraction of white strands (u_color is their mean)
uniform float u_end_height;   // hair, wisps: where long hair ends (y on the neutral face, dm) ...
uniform float u_end_fade;     // ... its strands ending one by one over this height above it
uniform vec3 u_hair_apex;     // hair: a point above the crown the strands flow down and out from (world)
uniform vec3 u_hair_apex_rest; // ... the same on the neutral face (v_rest's space)
// How much the strand highlight follows the hair's flow over the volume rather than each card's tangent.
const float HIGHLIGHT_FLOW = 0.7;
// Straight hair's locks (see main): cells per decimetre on the neutral head (~6 mm), and the light
// left in the gaps between them for dark and for light hair (light hair scatters more into them).
const float LOCK_CELLS_PER_DM = 16.0;
const float LOCK_GAP_DARK = 0.5;
const float LOCK_GAP_LIGHT = 0.75;

out vec4 f_color;

// Greying hair: the fraction of white strands wanders from clump to clump (clump: clump
// coordinates), so grey hair shows darker and lighter locks, salt and pepper at the scale
// of clumps, rather than one flat grey; where clumps are finer than a pixel, the mean colour.
// (grey_clump: the clump's noise, [0, 1]; unresolved: 1 where clumps are finer than a pixel)
vec3 grey_clump_colour(float grey_clump, float unresolved) {
    float local = clamp(u_grey + 0.6 * (grey_clump - 0.5), 0.0, 1.0);
    return mix(mix(u_pigment, u_white, local), u_color, unresolved);
}
vec3 hair_colour(vec2 clump) {
    if (u_grey <= 0.0) return u_color;
    return grey_clump_colour(value_noise(clump, 0),
                             clamp(0.5 * max(fwidth(clump.x), fwidth(clump.y)) - 0.25, 0.0, 1.0));
}

// Value noise in 3D on the integer lattice, [0, 1] (callers pick or fade the octave).
float lattice_noise3(vec3 p) {
    vec3 i = floor(p);
    vec3 f = p - i;
    vec3 u = f * f * (3.0 - 2.0 * f);
    ivec3 c = ivec3(i);
    int z0 = 7919 * c.z, z1 = 7919 * (c.z + 1);
    float a = mix(mix(hash2(ivec2(c.x, c.y + z0)), hash2(ivec2(c.x + 1, c.y + z0)), u.x),
                  mix(hash2(ivec2(c.x, c.y + 1 + z0)), hash2(ivec2(c.x + 1, c.y + 1 + z0)), u.x), u.y);
    float b = mix(mix(hash2(ivec2(c.x, c.y + z1)), hash2(ivec2(c.x + 1, c.y + z1)), u.x),
                  mix(hash2(ivec2(c.x, c.y + 1 + z1)), hash2(ivec2(c.x + 1, c.y + 1 + z1)), u.x), u.y);
    return mix(a, b, u.z);
}

// The same, faded to its mean where its cells are finer than a pixel.
float value_noise3(vec3 p) {
    return mix(0.5, lattice_noise3(p), clamp(2.0 - 1.4 * length(fwidth(p)), 0.0, 1.0));
}

// The same over a card's strand coordinates (``uv``, with ``base`` cells per texture unit across
// and along the strands), for textures whose strands run along v throughout: long cards' strands
// then run unbroken from root to tip (cells grow only with the square root along them).
float pixel_strands_uv(vec2 uv, vec2 base, vec2 offset) {
    float cells = max(fwidth(uv.x * base.x), 1e-5);   // base cells per pixel across the strands
    float level = log2(0.45 / cells);
    float k = clamp(floor(level), 0.0, 3.0);
    float f = clamp(level - k, 0.0, 1.0) * step(k, 2.5);
    float s0 = exp2(k);
    float n0 = value_noise(uv * base * vec2(s0, sqrt(s0)) + offset, 0);
    float n1 = value_noise(uv * base * vec2(2.0 * s0, sqrt(2.0 * s0)) + offset + 17.0, 0);
    float n = 0.5 + (mix(n0, n1, f) - 0.5) / sqrt(f * f + (1.0 - f) * (1.0 - f));
    return mix(0.5, n, clamp(2.2 - 1.6 * cells, 0.0, 1.0));
}

// Strands and clumps about two pixels across at any size: value noise on the neutral head
// (``rest``, dm; so it runs on across the cards' edges and moves with the hair), smeared along
// the strands (``along``; three samples over two cells and a bit, a short line-integral
// convolution: a global coordinate along a curving direction would shear the pattern), with
// ``cells_per_dm`` cells to the decimetre, taken at the octave whose cells come nearest two
// pixels across (at most 4x finer), blended with the next one so nothing pops as the hair
// nears or leaves the camera. Noise of fixed frequency fades to its mean at stimulus sizes (a
// flat, clay-like mass); this keeps strand-level variation in every image. [0, 1], mean 0.5.
float smeared_noise(vec3 p, vec3 step) {
    return (lattice_noise3(p - 2.0 * step) + lattice_noise3(p - step) + lattice_noise3(p)
            + lattice_noise3(p + step) + lattice_noise3(p + 2.0 * step)) * 0.2;
}

// The strands' octave for a noise of ``cells`` base cells per pixel: (scale s0, blend f toward
// the next octave). Two octaves are blended only near the switch from one to the next (each
// costs llvmpipe twenty-four hashes); elsewhere one is taken.
vec2 strand_octave(float cells) {
    float level = log2(0.6 / cells);
    float k = clamp(floor(level), 0.0, 2.0);
    return vec2(exp2(k), smoothstep(0.35, 0.65, clamp(level - k, 0.0, 1.0)) * step(k, 1.5));
}

// The two octaves' noises n0, n1 blended by f, their contrast restored by ``contrast``; where
// even the coarsest octave is finer than a pixel, their mean.
float strand_blend(float n0, float n1, float f, float contrast, float cells) {
    float n = 0.5 + contrast * (mix(n0, n1, f) - 0.5) / sqrt(f * f + (1.0 - f) * (1.0 - f));
    return mix(0.5, clamp(n, 0.0, 1.0), clamp(2.2 - 1.6 * cells, 0.0, 1.0));
}

float pixel_strands(vec3 rest, vec3 along, float cells_per_dm) {
    vec3 p = rest * cells_per_dm;
    float cells = max(length(fwidth(p)), 1e-5);  // base cells per pixel
    vec2 octave = strand_octave(cells);
    float n0 = octave.y < 0.999 ? smeared_noise(p * octave.x + 3.0, 1.2 * along) : 0.5;
    float n1 = octave.y > 0.001 ? smeared_noise(p * (2.0 * octave.x) + 11.0, 1.2 * along) : 0.5;
    // (a mean of three samples along a few cells varies ~1/1.5 as much as one; most of that
    // is given back, not all, so the darkest strands do not stand out as dots)
    return strand_blend(n0, n1, octave.y, 1.35, cells);
}

const float HAIR_VOLUME_RADIUS = 0.9;   // dm, facsim.render.proxies.VOLUME_RADIUS
// The volume's dome sits on this height (its apex, a quarter radius above the crown, on the axis).
float dome_base(vec3 apex) {
    return apex.y - 1.25 * HAIR_VOLUME_RADIUS;
}
// The point of the volume's vertical axis nearest p: under the dome, level with p.
vec3 volume_axis_point(vec3 p, vec3 apex) {
    return vec3(apex.x, min(p.y, dome_base(apex)), apex.z);
}

// Strands a couple of pixels across and many long, running down the hair volume's meridians
// from its axis (over the crown, then down the sides: facsim.render.proxies.volume_normals'
// dome) on the neutral head (``rest``, dm): value noise over the horizontal direction from the
// axis (``cells_per_dm`` cells across at the volume's radius) that changes only slowly with the
// distance from the apex above the crown (``stretch`` times slower), so each cell is drawn out
// into a streak along the flow. A smooth function of the place on the head: unlike a
// coordinate along a direction that turns from pixel to pixel it never shears, and it costs
// one noise per octave. (pixel_strands' few samples along the strands drew cells two or three
// long: at stimulus sizes george's grey short hair read as mottled stone, blind review
// session 23.) Octaves as in pixel_strands. [0, 1], mean 0.5.
float flow_strands(vec3 rest, float cells_per_dm, float stretch) {
    vec2 out_dir = rest.xz - u_hair_apex_rest.xz;
    out_dir /= max(length(out_dir), 1e-4);
    float along = length(rest - u_hair_apex_rest);
    vec3 across = vec3(out_dir.x, 0.0, out_dir.y) * (HAIR_VOLUME_RADIUS * cells_per_dm);
    // (each streak starts and ends at its own place along the flow, and the lattice lies at 45
    // degrees to the head's axes: on the lattice as it was, neighbouring streaks ended level
    // with one another, in rows of bricks over light hair)
    float stagger = 3.0 * lattice_noise3(across * 0.7 + 5.0);
    vec3 p = vec3(0.7071 * (across.x + across.z), along * cells_per_dm / stretch + stagger,
                  0.7071 * (across.z - across.x));
    float cells = max(length(fwidth(p)), 1e-5);
    vec2 octave = strand_octave(cells);
    float n0 = octave.y < 0.999 ? lattice_noise3(p * octave.x + 3.0) : 0.5;
    float n1 = octave.y > 0.001 ? lattice_noise3(p * (2.0 * octave.x) + 11.0) : 0.5;
    return strand_blend(n0, n1, octave.y, 1.1, cells);
}

// Where straight hair's locks lie, laid out like flow_strands at the locks' scale: the coordinate (main()
// takes value noise of it) of the horizontal direction from the volume's axis (LOCK_CELLS_PER_DM across at its radius) that changes
// LOCK_STRETCH times slower with the distance from the apex, so each lock runs several centimetres
// down the hair's flow as one piece. (Smeared over a few cells along each strand, the locks were
// blobs two or three cells long that drew a dappled, camouflage-like pattern across the lengths:
// a "textured helmet", blind review session 24; stretched 7 times, the partings between them
// still closed round each lock as contour lines, wood grain in a profile view.) main() fades the
// noise to its mean where finer than a pixel.
// (The coordinate, not the noise, so its screen-space change is taken outside any branch.)
const float LOCK_STRETCH = 25.0;
vec3 flow_lock_coordinate(vec3 rest) {
    vec2 out_dir = rest.xz - u_hair_apex_rest.xz;
    out_dir /= max(length(out_dir), 1e-4);
    float along = length(rest - u_hair_apex_rest);
    return vec3(out_dir.x, 0.0, out_dir.y) * (HAIR_VOLUME_RADIUS * LOCK_CELLS_PER_DM)
         + vec3(0.0, along * LOCK_CELLS_PER_DM / LOCK_STRETCH, 0.0);
}

// The narrow gap between two locks: where the lock noise crosses its mean, a connected network of
// lines running along the locks (not dark spots on a light field): 1 in a gap ... 0 on a lock.
float lock_gap(float lock) {
    return 1.0 - smoothstep(0.01, 0.09, abs(lock - 0.5));
}

#if defined(USE_SHADOW) && defined(KIND_HAIR)
// How much of the key reaches p (world; n: the volume's normal) inside the hair's mass, a
// cheap deep-opacity map: the shadow map holds the depth of the first thing the key meets,
// and the light a strand gets falls off with the depth of hair between it and that first
// caster, exp(-depth / free_path) (a strand in the outer layer keeps it all, the under-layers
// a few millimetres in get less, the hair under the mass of an afro or under the crown's
// overhang little), down to what the caster lets through (its opacity: hair, less for light
// hair; skin, none: the head's shadow on the hair). Two hardware comparisons (each a 2x2 PCF)
// give how much of the footprint has its first caster within 2 mm (the strand's own card)
// and within 10 mm before p.
float hair_key_visibility(vec3 p, vec3 n, float free_path_mm) {
    vec3 c = (u_shadow_matrix * vec4(p + n * u_shadow_texel, 1.0)).xyz;
    float mm = 0.01 / u_shadow_depth_range;   // one millimetre in the map's depth
    float own = texture(u_shadow, vec3(c.xy, c.z - 2.0 * mm));
    float near = texture(u_shadow, vec3(c.xy, c.z - 10.0 * mm));
    // (a caster 2-10 mm before p: the light through the hair between, taken at 6 mm; further: all it stops)
    float stopped = (near - own) * (1.0 - exp(-6.0 / free_path_mm)) + (1.0 - near);
    float opacity = texture(u_shadow_opacity, c.xy).r;
    float inside = step(0.0, c.x) * step(c.x, 1.0) * step(0.0, c.y) * step(c.y, 1.0) * step(c.z, 1.0);
    return 1.0 - stopped * opacity * inside;
}
#endif

#if defined(USE_SHADOW) && defined(KIND_HAIR) && defined(COILY)
// The key's shadow on coily hair: only what lies more than 10 mm before p (the head, the mass's
// far side). The cards a few millimetres before p shadowed the card behind them along their
// edges, drawing the cards as dark patches in the mass; its self-shadow at that scale is the
// clumps' (coily_self_shadow). (A 2x2 PCF comparison, as hair_key_visibility's.)
float coily_key_visibility(vec3 p, vec3 n) {
    vec3 c = (u_shadow_matrix * vec4(p + n * u_shadow_texel, 1.0)).xyz;
    float mm = 0.01 / u_shadow_depth_range;
    float near = texture(u_shadow, vec3(c.xy, c.z - 10.0 * mm));
    float opacity = texture(u_shadow_opacity, c.xy).r;
    float inside = step(0.0, c.x) * step(c.x, 1.0) * step(0.0, c.y) * step(c.y, 1.0) * step(c.z, 1.0);
    return 1.0 - (1.0 - near) * opacity * inside;
}
#endif

// Kajiya-Kay: light scattered by a thin cylinder along t.
float strand_diffuse(vec3 t, vec3 l) {
    float tl = dot(t, l);
    return sqrt(max(1.0 - tl * tl, 0.0));
}


// How far p lies inside coily hair's outline seen from the eye (mm), measured on the smooth
// volume the hair is shaded as (a dome over a vertical axis, facsim.render.proxies.
// volume_normals, without the cards' own normals; a sphere's radius r seen at cos = n.v lies
// r (1 - sin) inside), so the outline's clumps of coils (COILY_BUMP_MM) stand out of a rounded
// mass, not of the cards' polygonal cut. Within COILY_EDGE_MM of it the cut and the coily
// wisps' fade act (further in, the blended pass skips solid fragments).
const float COILY_EDGE_MM = 3.0;
float coily_inside_outline_mm(vec3 p, vec3 v) {
    vec3 out_dir = p - volume_axis_point(p, u_hair_apex);
    float r = length(out_dir);
    float c = clamp(dot(out_dir, v) / max(r, 1e-6), 0.0, 1.0);
    return 100.0 * r * (1.0 - sqrt(1.0 - c * c));
}

#ifdef KIND_HAIR
// The hair colour's hue at full brightness, halfway from white: what tints its highlights.
vec3 hair_tint() {
    return mix(vec3(1.0), u_color / max(max(u_color.r, u_color.g), max(u_color.b, 1e-4)), 0.5);
}
#endif

#ifdef COILY
// Lattices turned against each other and the head's axes (an axis-aligned one drew rows of bricks).
const mat3 COIL_TURN_A = mat3(0.788, 0.418, -0.452, -0.360, 0.908, 0.214, 0.500, -0.017, 0.866);
const mat3 COIL_TURN_B = mat3(0.643, -0.543, 0.540, 0.766, 0.456, -0.453, 0.000, 0.705, 0.709);

// Single coils: tightly coiled hair at stimulus sizes is a surface of small round coils, each
// a little dome with its own glint on its side toward the light and shade in the crevices round
// it (smooth noise at that scale read as a blurred, foamy mass: "blobby afro", blind review
// session 25). The nearest of jittered points on a lattice of COIL_CELLS_PER_DM cells (Worley's
// F1 over the 2x2x2 cells nearest q), each a ball of its own radius, cut by the surface. Taken
// on the neutral head in 3-D (q: v_rest, dm), not by direction from the volume's axis as the
// clumps are: the coils are small enough that the cards' layers do not show as seams, and by
// direction they stretched into streaks where the cards run radially. n: the volume's normal.
// Returns the dome's normal (its slope in the tangent plane added to n) in .xyz and its height
// (0 between coils ... 1 at its top) in .w; id: the coil's own random number; detail: 1 where
// a coil spans a few pixels ... 0 where it is under a pixel and a half (callers fade to the mean).
const float COIL_CELLS_PER_DM = 42.0;   // ~2.4 mm
vec4 coil_dome(vec3 q, vec3 n, out float detail, out float id) {
    vec3 s = COIL_TURN_A * q * COIL_CELLS_PER_DM + 11.0;
    vec3 base = floor(s - 0.5);
    float best = 9.0;
    vec3 best_d = vec3(0.0);
    float best_r = 0.6;
    id = 0.5;
    for (int k = 0; k < 8; ++k) {
        vec3 cell = base + vec3(float(k & 1), float((k >> 1) & 1), float((k >> 2) & 1));
        ivec3 c = ivec3(cell);
        float h = hash2(ivec2(c.x + 7919 * c.z, c.y));
        vec3 jitter = fract(h * vec3(1.0, 37.13, 91.71));
        vec3 d = s - (cell + 0.15 + 0.7 * jitter);
        float r = 0.5 + 0.25 * fract(h * 13.37);
        float e = dot(d, d) / (r * r);
        if (e < best) { best = e; best_d = d; best_r = r; id = h; }
    }
    float dome = sqrt(max(1.0 - best, 0.0));
    vec3 slope = transpose(COIL_TURN_A) * best_d / best_r;
    slope -= dot(slope, n) * n;
    detail = clamp(3.0 - 3.0 * length(fwidth(s)), 0.0, 1.0);
    return vec4(normalize(n * max(dome, 0.05) + 0.8 * slope), dome);
}
#endif

#if defined(KIND_HAIR) && defined(COILY)
// Coily hair's clumps of coils, placed on the neutral head (rest, dm) by their direction from
// the volume's axis (at the volume's radius): the cards lie in layers a few millimetres apart,
// and noise taken at each card's own depth jumped at every card's edge (a seam across the
// mass); by direction, the card in front and the one behind it show the same clump, and the
// clumps standing out of the outline (COILY_BUMP_MM) form one height field around the mass.
// Clumps ~8 mm and ~4 mm across and coils ~2 mm in lattices turned against each other and the
// head's axes (an axis-aligned one drew rows of bricks). [0, 1], mean 0.5; each faded to its
// mean where finer than a pixel (value_noise3).
const float COILY_BUMP_MM = 2.5;   // how far the clumps stand out of the mass at its outline
vec3 coil_place(vec3 rest) {
    vec3 axis = volume_axis_point(rest, u_hair_apex_rest);
    return axis + normalize(rest - axis + vec3(0.0, 1e-5, 0.0)) * HAIR_VOLUME_RADIUS;
}
float coily_clumps(vec3 q) {
    return 0.25 * value_noise3(COIL_TURN_B * q * 12.0 + 7.0) + 0.4 * value_noise3(COIL_TURN_A * q * 25.0 + 1.0)
         + 0.35 * value_noise3(COIL_TURN_B * q * 50.0 + 3.0);
}

// Coily hair is a dense mass: it shadows itself toward its underside (n: the volume's normal
// turned down), where it overhangs the forehead and the temples, and its clumps' hollows lie in
// their crowns' shade (crown). Only the mass's broad shape counts, not which card is drawn
// where: the cards' layers (v_depth) and UV noise drew the cards' shapes as dark patches in it.
// The mass is lit more the higher it stands (height: dm over the dome's base, about the top of
// the forehead): its top takes the key and the sky, its lower part over the forehead and the
// temples lies deeper in the hair's own shade (one even tone from crown to temples read as a
// helmet of foam, blind review session 25).
float coily_self_shadow(vec3 n, vec3 v, float crown, float height) {
    float underside = mix(0.45, 1.0, smoothstep(-0.55, 0.35, n.y)) * mix(0.72, 1.1, smoothstep(-0.5, 0.6, height));
    // (light falls off a little into the mass where the eye looks straight in)
    float facing = mix(0.9, 1.0, 1.0 - clamp(dot(n, v), 0.0, 1.0));
    return underside * facing * mix(0.85, 1.0, crown);
}

// Coils face every way: their highlight is a broad soft sheen where the mass faces the key
// light, carried by the coils' crowns (crown: 0 crevice ... 1 crown), not the strand lobes of
// straight hair, which the cards' tangents drew as pale scratches across the mass.
vec3 coily_sheen(vec3 n, vec3 v, float crown) {
    vec3 h = normalize(u_key_dir + v);
    vec3 tint = hair_tint();
    return u_key_col * tint * 0.07 * pow(max(dot(n, h), 0.0), 4.0) * mix(0.5, 1.0, crown);
}
#endif

#ifdef KIND_SCALP
// Coily hair on the scalp is placed on the neutral head (v_rest) in lattices turned against the
// head's axes (an axis-aligned one drew a grid of dots).
const mat3 crop_turn = mat3(0.788, 0.418, -0.452, -0.360, 0.908, 0.214, 0.500, -0.017, 0.866);
#ifdef CROP
// A close crop (facsim/head/scalp.py; no cards over it): coily hair a few millimetres long is
// all the hair there is. v_cover: the distance inside its hairline in widths of the band over
// which the hair thins (scalp.CROP_EDGE; linear across the skin's triangles, so the hairline
// is placed per pixel, not along the mesh's edges); v_rest: the neutral head, where the coils lie.

// The hair's cover (0 bare skin ... 1 solid) at the hairline: it wanders by a few millimetres
// (tufts grow forward, gaps recede, clump by clump) and thins over the band from solid hair to
// single hairs with skin between them, never a line.
float crop_cover() {
    vec3 p = crop_turn * v_rest;
    float wander = 0.6 * (value_noise3(p * 9.0 + 1.0) - 0.5) + 0.6 * (value_noise3(p * 40.0 + 2.0) - 0.5);
    float dens = clamp(v_cover + wander, 0.0, 1.2);
    // Hairs a fraction of a millimetre apart (their mean where finer than a pixel): each is
    // there where its rank is under the density, so the band thins hair by hair.
    float rank = value_noise3(transpose(crop_turn) * v_rest * 160.0 + 4.0);
    float hairs = smoothstep(rank - 0.3, rank + 0.3, dens);
    // Inside the band the short hairs hide the skin but for a glimpse between them.
    return min(hairs * dens * sqrt(dens), 1.0) * 0.96;
}

vec4 close_crop() {
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_cam_pos - v_pos);
    float alpha = crop_cover();
    // Seen at a slant the eye crosses more of the hairs (transmittance to the power 1 / cos):
    // toward the head's outline they hide the skin ...
    float facing = abs(dot(n, v));
    alpha = 1.0 - pow(1.0 - min(alpha, 0.999), 1.0 / max(facing, 0.08));
    // ... and at the outline itself the coils stand apart against the background: a fuzzy
    // edge of curls a millimetre or two across, not the layer's smooth cut.
    vec3 p = crop_turn * v_rest;
    float curls = 0.65 * lattice_noise3(p * 35.0 + 6.0) + 0.35 * value_noise3(p * 100.0 + 9.0);
    alpha *= mix(1.0, smoothstep(0.4, 0.6, curls), 1.0 - smoothstep(0.04, 0.16, facing));
    // Coils a millimetre and a few millimetres across, placed on the neutral head so they are
    // round and move with the skin, with dark crevices between them: the crop catches the
    // light unevenly, coil by coil, as the tips of a pile do. (lattices turned against the
    // head's axes: an axis-aligned one drew a grid of dots)
    float kink = value_noise3(p * 110.0);
    float coils = value_noise3(transpose(crop_turn) * v_rest * 35.0 + 5.0);
    float tips = kink * (0.6 + 0.8 * coils);
    float kl = clamp(dot(n, u_key_dir) * 0.5 + 0.5, 0.0, 1.0);
    float dk = kl * kl * 1.25;   // coils face every way: no strand direction
#ifdef USE_SHADOW
    float key_reach = key_visibility(v_pos, n);   // the ears', the head's shadow
#else
    float key_reach = 1.0;
#endif
    float df = clamp(dot(n, u_fill_dir) * 0.5 + 0.5, 0.0, 1.0);
    vec3 lit = dk * key_reach * u_key_col + df * u_fill_col + hemisphere(n) * 0.8;
    // A broad, soft sheen where the pile faces the key light, carried by the coils' tips.
    vec3 h = normalize(u_key_dir + v);
    vec3 sheen = key_reach * u_key_col * 0.1 * u_sheen * pow(max(dot(n, h), 0.0), 6.0) * smoothstep(0.35, 0.8, tips);
    // Greying: white and pigmented coils mixed clump by clump, placed on the head in 3-D (a
    // pattern in two of its coordinates ran as streaks along the third, across the temples).
    vec3 colour = u_color;
    if (u_grey > 0.0)
        colour = mix(u_pigment, u_white, clamp(u_grey + 0.35 * (coils - 0.5) + 0.3 * (value_noise3(p * 20.0 + 3.0) - 0.5), 0.0, 1.0));
    vec3 albedo = colour * (0.55 + 0.9 * tips) * 0.85;
    return vec4(finish(albedo * lit + sheen).rgb, alpha);
}
#endif

// The fine hair growing on the skin under a hairstyle's cards (facsim/head/scalp.py): drawn
// blended over the skin before the cards, so the scalp between and beyond them is covered by
// hair of the cards' colour, thinning over a centimetre at the hairline into single hairs with
// the skin between them, instead of ending in a seam of bare, shadowed skin.
// v_uv: strand coordinates in texture tiles (u across, v along the hair's flow); v_depth: the
// hair's density there (0 bare ... 1 full cover). tex: R brightness, G each strand's rank, A cover.
void main() {
#ifdef PASS_OPAQUE
    discard;
#endif
#ifdef CROP
    f_color = close_crop();
    if (f_color.a < 0.01) discard;
#else
    // Coily hair grows in small round curls, not long strands: the tile's tufts squashed round.
#ifdef COILY
    vec2 suv = v_uv * vec2(2.0, 6.0);
#else
    vec2 suv = v_uv;
#endif
    vec4 tex = texture(u_texture, suv);
    // Tufts (tex.g: their rank) are kept where their rank is under the density: a thinning
    // hairline breaks into separate tufts and single hairs. Their edges soften where a tuft
    // nears a pixel across (the rank's screen-space change), never alias.
    float w = 0.04 + 1.5 * fwidth(tex.g);
    // The hairline wanders by a few millimetres (clumps grow forward, gaps recede), so its
    // tufts do not line up along the mesh's edge like teeth.
    float wander = value_noise(v_uv * vec2(2.5, 0.8) + 11.0, 0) - 0.5;
    float dens = v_depth * 1.08 - 0.04 + 1.3 * wander * v_depth * (1.0 - v_depth);
    float keep = smoothstep(tex.g - w, tex.g + w, dens);
    // Where the cover thins, the hairs that are left are finer and fewer: the tuft's own
    // strands (tex.a) show more of the skin between them, so the hairline ends in wisps.
    float alpha = mix(tex.a * tex.a * tex.a, tex.a, smoothstep(0.2, 0.9, dens));
#ifndef COILY
    // Tufts finer than a pixel (texels of the tile per pixel across the strands; 448-512²
    // stimuli): their mean cover drew the hairline as an even translucent film of the hair's
    // colour over the forehead, a brim under the cards. Strands and clumps a few pixels across
    // along the flow (pixel_strands_uv) take their place: each there where its rank is under
    // the density, so the band thins into streaks of hair with skin between them.
    float sub = smoothstep(16.0, 40.0, fwidth(suv.x) * 256.0);
    float strands_px = pixel_strands_uv(suv, vec2(4.0, 1.5), vec2(3.0, 7.0));
    float streak = clamp(0.5 + 2.2 * (strands_px - 0.5), 0.02, 0.98);
    // Larger tufts (1024², or where the UVs are dense above the forehead) are soft wedges whose
    // translucent cover drew light hair as a film (george's grey hairline, blind review,
    // session 21): their cover is the share of those strands there, each solid, so a tuft
    // thins toward its tip into strands with skin between them.
    float tuft_alpha = smoothstep(streak - 0.06, streak + 0.06, 1.25 * alpha);
    alpha = mix(tuft_alpha, alpha, sub);
    keep = mix(keep, smoothstep(streak - 0.1, streak + 0.1, dens), sub);
    alpha = mix(alpha, mix(0.6, 1.0, smoothstep(0.3, 0.9, dens)), sub);
#else
    // Tufts finer than a pixel show only as their mean cover (the coils below break it up).
    keep = mix(keep, clamp(dens, 0.0, 1.0), smoothstep(16.0, 40.0, fwidth(suv.x) * 256.0));
#endif
    alpha *= keep * 0.92;
    if (alpha < 0.01) discard;
    vec3 n = normalize(v_normal);
    vec3 t = normalize(v_tangent);
    float kl = clamp(dot(n, u_key_dir) * 0.5 + 0.5, 0.0, 1.0);
    float dk = mix(strand_diffuse(t, u_key_dir), 1.0, 0.3) * kl * kl * 1.25;
    // The hairs within about a centimetre of the hairline (v_cover: the height above it in
    // centimetres, facsim.head.scalp.ScalpLayer.hairline) grow in the open, as the cards' outer
    // strands do: the cards' edge stands a few millimetres off the forehead, and its shadow
    // and the roots' shade drew the hairs under it as a dark brim along the hairline ("helmet
    // hair / hair cap edge", blind review session 23). They take the key light unshadowed.
    float in_open = 1.0 - smoothstep(0.6, 1.5, v_cover);
#ifdef USE_SHADOW
    dk *= mix(key_visibility(v_pos, n), 1.0, in_open);   // under the cards' shadow, as the skin it lies on
#endif
    float df = clamp(dot(n, u_fill_dir) * 0.5 + 0.5, 0.0, 1.0);
    vec3 lit = dk * u_key_col + df * u_fill_col + hemisphere(n) * 0.8;
    // The roots under full cover lie in the cards' shadow; the hairline's fine hairs in the open.
    float light_hair = sqrt(clamp(dot(u_color, LUMINANCE), 0.0, 1.0));
    // Brightness strand by strand (coily: curl by curl), not one flat tone.
#ifdef COILY
    float strand_shade = 1.0;
#else
    float strand_shade = 0.75 + 0.5 * strands_px;
#endif
#ifdef COILY
    {
        // Coily hair at the hairline: curls a millimetre and a few millimetres across, placed on
        // the head like the cards' and a crop's (the tile's own curls are finer than a pixel at
        // stimulus sizes and left a smooth pale film along the hairline, a brim under the mass),
        // with skin between them where the cover thins; the roots under full cover lie in the
        // mass's shade, darker than straight hair's whatever the colour (the mass is dense).
        vec3 p = crop_turn * v_rest;
        float kink = value_noise3(p * 110.0);
        float coils = value_noise3(transpose(crop_turn) * v_rest * 35.0 + 5.0);
        strand_shade = (0.55 + 0.9 * kink) * (0.6 + 0.8 * coils);
        alpha *= smoothstep(0.3, 0.7, 0.55 * coils + 0.45 * kink + 0.35 * (dens - 0.6));
        // Where a pixel resolves them, the mass's single coils (coil_dome): each solid, there
        // where its rank is under the density, so the hairline ends in short coils standing
        // apart on the skin, not in a soft dark film along a clean line (blind review session 25).
        // (the hairline's hairs are shorter and finer than the mass's: coils 1.4 times smaller,
        // over a little of the fine cover they grow from)
        float detail, rank;
        vec4 coil = coil_dome(v_rest * 1.4, n, detail, rank);
        float present = smoothstep(rank - 0.08, rank + 0.08, 1.6 * dens - 0.1);
        float disc = clamp(0.5 + (coil.w - 0.2) / max(fwidth(coil.w), 0.05), 0.0, 1.0);
        alpha = mix(alpha, max(0.3 * alpha, 0.95 * present * disc), detail);
        float coil_key = clamp(dot(coil.xyz - n, u_key_dir) + 0.5, 0.0, 1.0);
        strand_shade = mix(strand_shade, mix(0.6, 1.2, coil.w) * (0.7 + 0.6 * coil_key) * (0.85 + 0.3 * rank), detail);
        light_hair *= 0.4;
    }
#endif
    float shade = mix(0.9, mix(0.35, 0.7, light_hair), smoothstep(0.3, 1.0, v_depth) * (1.0 - in_open));
    vec3 albedo = hair_colour(suv * vec2(8.0, 2.0)) * (0.55 + 0.9 * tex.r) * shade * strand_shade;
    f_color = vec4(finish(albedo * lit).rgb, alpha);
#endif
}
#elif defined(KIND_WISPS)
// Loose strands over the hair (facsim/head/wisps.py): thin ribbons turned toward the camera
// (proxy.vert.glsl), drawn blended after the cards in the hair's colour. v_depth: 0 at the
// root ... 1 at the tip; v_cover: the share of the drawn width the strand covers; tex.a: the
// cover across the ribbon (soft at its sides).
void main() {
#ifdef PASS_OPAQUE
    discard;
#endif
    vec4 tex = texture(u_texture, v_uv);
    // Faint where it leaves the mass, then thinning to nothing at the tip.
    float alpha = tex.a * v_cover * u_density * smoothstep(0.0, 0.15, v_depth) * (1.0 - smoothstep(0.55, 1.0, v_depth))
                * smoothstep(0.3, 1.0, (v_rest.y - u_end_height) / u_end_fade);   // none where long hair ends
    vec3 v = normalize(u_cam_pos - v_pos);
    // Coily wisps thin out over the mass's outline band (coily_inside_outline_mm): coils on the
    // cards that stand out edge-on past it floated as a grey lace beside the mass.
    if (u_coil > 0.0)
        alpha *= mix(1.0, smoothstep(-1.0, COILY_EDGE_MM,
                                     coily_inside_outline_mm(v_pos, v)), u_coil);
    if (alpha < 0.01) discard;
    vec3 n = normalize(v_normal);
    vec3 t = normalize(v_tangent);
    float kl = clamp(dot(n, u_key_dir) * 0.5 + 0.5, 0.0, 1.0);
    float dk = strand_diffuse(t, u_key_dir) * kl * 1.1;
    float df = clamp(dot(n, u_fill_dir) * 0.5 + 0.5, 0.0, 1.0);
    // Stray hairs against the background catch the rim light through their edges.
    float dr = clamp(dot(n, u_rim_dir) * 0.5 + 0.5, 0.0, 1.0);
    vec3 lit = dk * u_key_col + df * u_fill_col + 0.5 * dr * u_rim_col + hemisphere(n) * 0.7;
    vec3 h = normalize(u_key_dir + v);
    float th = dot(t, h);
    vec3 spec = u_key_col * 0.12 * u_sheen * exp2(30.0 * log2(max(1.0 - th * th, 1e-6)));
    vec3 albedo = hair_colour(v_uv * vec2(1.0, 3.0) + v_rest.xy * 40.0);
    f_color = vec4(finish(albedo * lit * 0.75 + spec).rgb, alpha);
}
#else
#ifdef KIND_EYEBROWS
// The brow's outline is hairs, not a drawn contour: each texture column (a few hairs wide on
// screen, slanted as brow hairs grow, up and toward the tail) is read a little above or below
// its place, so single hairs stick out past the band's edge and gaps open in it. MakeHuman's
// brow textures are ~10x finer than a 448-px brow: minified, their own stray hairs blur into
// a smooth band with a crisp contour, a brow painted on (issue 13, mei's eyebrow004).
// Two sizes of column (per texture unit along u), the finer faded where it would be under a
// pixel; BROW_FEATHER: the largest shift across the brow (texture v; a brow is ~0.1 tall).
const vec2 BROW_HAIR_COLUMNS = vec2(45.0, 150.0);
const float BROW_HAIR_SLANT = 0.6;   // how far a column leans toward the tail per unit it rises
const float BROW_FEATHER = 0.022;
vec2 brow_feather(vec2 uv) {
    vec2 q = vec2(uv.x + BROW_HAIR_SLANT * uv.y, 0.0);
    float coarse = value_noise(vec2(q.x * BROW_HAIR_COLUMNS.x, 17.5), 0) - 0.5;
    float fine = value_noise(vec2(q.x * BROW_HAIR_COLUMNS.y, 3.5), 0) - 0.5;
    float fine_detail = clamp(1.5 - fwidth(q.x * BROW_HAIR_COLUMNS.y), 0.0, 1.0);
    return uv + vec2(0.0, BROW_FEATHER * (coarse + fine_detail * fine));
}
#endif
#if defined(KIND_HAIR) && !defined(COILY)
// MakeHuman's straight-hair textures fade their strands' tips over the last centimetre or two
// of a card: where cards end over the skin (a fringe over the forehead, short01's front edge)
// that fade drew a see-through band of brown film with the skin showing through it. Strands
// are dense to near their tips: the fade is steepened into the last few millimetres, where
// the strands end one by one (the fraying below), and the gaps between strands stay open.
float dense_tips(float alpha) {
    return smoothstep(0.04, 0.42, alpha);
}
#endif

void main() {
#ifdef KIND_EYEBROWS
    // (The shifted lookup keeps the unshifted one's filter footprint: its columns' jumps
    // would otherwise pick blurred mip levels.)
    vec4 tex = textureGrad(u_texture, brow_feather(v_uv), dFdx(v_uv), dFdy(v_uv));
#else
    vec4 tex = texture(u_texture, v_uv);
#endif
    float alpha = tex.a;
#if defined(KIND_HAIR) && !defined(COILY)
    alpha = dense_tips(alpha);
#endif
#if defined(KIND_EYEBROWS) || defined(KIND_EYELASHES)
    // Brows and lashes are one thin layer of fine hairs: drawn whole in the blended pass and
    // translucent, so skin shows between the hairs and they read as hair, not paint. Their
    // hairs are finer than a pixel in most stimuli; the mipmapped alpha is then the fraction
    // of the skin they cover, scaled by the character's density (sparser with age).
#ifdef PASS_OPAQUE
    discard;
#endif
#ifdef KIND_EYEBROWS
    // v_depth: 0 at the brow's head ... 1 at its tail. The head's hairs grow upward, spaced,
    // so skin shows through (a solid dark head reads as a frown); the tail thins out.
    // (The head fades in over its first ~4 mm: at half strength to its end, its cut edge drew
    // the square end of a pencil stroke.)
    float thin = mix(0.25, 1.0, smoothstep(0.0, 0.22, v_depth)) * mix(1.0, 0.55, smoothstep(0.7, 1.0, v_depth));
    // The texture's own strokes keep their contrast (doubling alpha filled dense brows such
    // as eyebrow012 into a flat painted strip, issue 13), with a fine breakup across them.
    float grain = value_noise(v_uv * vec2(260.0, 260.0), 0);
    grain = mix(0.5, grain, clamp(2.0 - 1.5 * fwidth(v_uv.x * 260.0), 0.0, 1.0));
    // Strokes a pixel or two across and several long, along the brow (MakeHuman's brow
    // textures run along u), wavering: they survive where the texture's own hairs have
    // blurred into their mean (448-512² stimuli), so the brow reads as hairs over skin, not
    // a painted strip. Faded out where even they would be finer than a pixel.
    float stroke = value_noise(vec2(v_uv.x * 14.0, v_uv.y * 70.0 + 2.5 * value_noise(v_uv * 6.0, 0)), 0);
    float stroke_detail = clamp(2.2 - 1.2 * fwidth(v_uv.y * 70.0), 0.0, 1.0);
    alpha = clamp(tex.a * 1.45, 0.0, 0.93) * mix(1.0, 0.45 + 1.0 * stroke, 0.85 * stroke_detail)
          * (0.75 + 0.5 * grain) * thin * u_density;
    alpha = min(alpha, 1.0);
#else
    // v_depth: 0 at the lid ... 1 at the lash tips: each lash tapers to a fine point, so
    // the lash line is dense at the lid margin (it gives the upper lid its dark edge) and the
    // tips fade instead of ending in spikes (lower lashes start part-way along, proxies.py).
    // At the roots the strands overlap into the dense, dark line that outlines a real eye
    // (the lash line): there the texture's gaps close up; the tips stay apart.
    alpha = clamp(tex.a * mix(1.7, 1.2, smoothstep(0.0, 0.4, v_depth)), 0.0, 1.0)
          * mix(1.0, 0.15, smoothstep(0.1, 1.0, v_depth)) * u_density;
#endif
    if (alpha < 0.01) discard;
#else
#ifdef KIND_HAIR
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_cam_pos - v_pos);
#ifdef COILY
    // Coily hair is lit as the smooth mass it is, not card by card (the cards' own normals and
    // strand tangents drew them as flat patches and bands across it).
    n = normalize(mix(n, normalize(v_pos - volume_axis_point(v_pos, u_hair_apex)), u_coil));
#endif
    // Fraying below only ever lowers alpha: fragments the texture alone settles are dropped
    // before the noise is computed (most of the blended pass's fragments are cards under the
    // outer layer, seen through its frayed gaps, that belong to the alpha-tested pass).
#if defined(PASS_OPAQUE) && defined(COILY)
    if (alpha < 0.02) discard;   // coily hair's texture holes are filled below (fill)
#elif defined(PASS_OPAQUE)
    if (alpha < ALPHA_CUTOFF) discard;
#else
#ifdef COILY
    // (coily hair is cut within its outline band, coily_inside_outline_mm, not only where n.v is low)
    if (alpha < 0.02 || (alpha >= ALPHA_CUTOFF && v_edge < 0.1 && v_cover > 0.999 && dot(n, v) >= 0.28
                         && coily_inside_outline_mm(v_pos, v) > COILY_EDGE_MM + 3.0)) discard;
#else
    if (alpha < 0.02 || (alpha >= ALPHA_CUTOFF && v_edge < 0.1 && v_cover > 0.999 && dot(n, v) >= 0.28)) discard;
#endif
#endif
#ifdef COILY
    // (the single coils under this pixel, coil_dome: the mass's thinning and its shading)
    float coil_detail, coil_id;
    vec4 coil = coil_dome(v_rest, n, coil_detail, coil_id);
    // (only at the outline, where the eye grazes the mass and each card layer shows its own
    // coils, do they fade out of the shading)
    coil_detail *= smoothstep(0.05, 0.25, dot(n, v));
    // (where a coil spans many pixels, 1024², the hairs wound in it break up its dome and its
    // glint: smooth domes read as beads)
    vec3 coil_hair_p = COIL_TURN_B * v_rest * 140.0;
    float coil_hair_fade = clamp(2.0 - 1.4 * length(fwidth(coil_hair_p)), 0.0, 1.0) * coil_detail;
    float coil_hairs = coil_hair_fade > 0.0 ? mix(1.0, 0.3 + 1.4 * lattice_noise3(coil_hair_p), coil_hair_fade) : 1.0;
#endif
    // Strand coordinates: across the strands (u) many, along them (v) few. Each noise fades
    // to its mean where it would be finer than a pixel, so small images do not shimmer.
    // Most of MakeHuman's hair textures run along v; where a texture's own strands turn away
    // (tex.gb from its structure tensor, e.g. a ponytail's crown) the breakup fades out
    // rather than cross the strands (u_along_v = 1 for textures running along v throughout).
    float along_v = max(u_along_v, smoothstep(0.75, 0.92, abs(tex.b * 2.0 - 1.0)));
    vec2 mp = v_uv * vec2(150.0, 2.5) + 3.0;
    float mid = mix(0.5, value_noise(mp, 0), along_v * clamp(2.0 - 1.4 * fwidth(mp.x), 0.0, 1.0));
    vec2 cp = v_uv * vec2(45.0, 1.2) + 7.0;
    float clump = mix(0.5, value_noise(cp, 0), along_v * clamp(2.0 - 1.5 * fwidth(cp.x), 0.0, 1.0));
    // Shading's strands and clumps: along the strands their phase also follows the card's
    // place on the head (v_rest). Cards of one row share their texture's v range, and noise
    // in v alone lit and darkened every card of a row alike: long01's crown drew its rows of
    // cards as horizontal bands.
    vec2 phase = vec2(0.0, dot(v_rest, vec3(3.1, 2.3, 2.7)));
    // Strands and clumps a couple of pixels across whatever the image size (pixel_strands).
    // Cards whose texture runs along v (long01, bob) take them in the cards' own strand
    // coordinates, unbroken from root to tip; the others (short02's swept sides, a ponytail's
    // crown) on the neutral head along the strands' direction, running on across the cards.
    // (Long cards' own texture strands carry most of their detail already: a strong breakup over
    // them draws dark blotches across the lengths.)
#ifdef COILY
    // (coily hair: its clumps of coils are placed on the neutral head, coily_clumps)
    float px = 0.5;
    float lock = 0.5;
    float lock_flow = 0.0;
    float parting_open = 1.0;
#else
    // Hair whose texture runs along v (u_along_v: long01, the bobs) hangs down and out from the
    // crown as a whole: its pixel-scale strands follow that flow everywhere (flow_strands), as do
    // its locks (below), the same pattern on every card. (On the crown its cards lie in rows
    // across the sideways strands, and strands in the cards' coordinates drew the rows as bands;
    // switched between the cards' coordinates and the head's by each card's own tangent, the
    // pattern changed at every card's edge: the crown's cards drew as blocks and wood grain,
    // "helmet hair", blind review session 25.)
    vec3 along_rest = normalize(v_rest_tangent + vec3(0.0, 1e-4, 0.0));
    // Short styles: where the strands run down and out from the crown (most of the mass), they
    // are streaks along that flow (flow_strands); where they turn away from it (a fringe falling
    // over the forehead, hair brushed sideways), short smears along their own direction (pixel_strands).
    float flow_share = 1.0;
    if (u_along_v < 0.5) {
        vec3 nv = normalize(v_rest - volume_axis_point(v_rest, u_hair_apex_rest));
        vec3 meridian = cross(nv, normalize(cross(vec3(0.0, 1.0, 0.0), nv) + vec3(1e-5, 0.0, 0.0)));
        flow_share = smoothstep(0.75, 0.92, abs(dot(meridian, along_rest)));
    }
    // (strands pointing at the eye are seen end-on: their streaks shrink to dots, which
    // speckled a fringe brushed forward; there the streaks fade to their mean)
    float tv = dot(normalize(v_tangent), normalize(u_cam_pos - v_pos));
    float seen_along = smoothstep(0.45, 0.8, sqrt(max(1.0 - tv * tv, 0.0)));
    float px_flow = flow_share > 0.001 ? mix(0.5, flow_strands(v_rest, 60.0, 8.0), seen_along) : 0.5;
    float px = flow_share > 0.999 ? px_flow : mix(pixel_strands(v_rest, along_rest, 60.0), px_flow, flow_share);
    // Long hair ends above u_end_height (MakeHuman's long cards hang on through the shoulders)
    // the way a cut bob does: clumps a few millimetres across end at a little different
    // lengths, and within each the strands end one by one over the last few millimetres, so
    // the ends thin out into fine tips. Each strand is solid to its tip (no translucent film:
    // faded cards showed the background through them as pale smears and streaks); only where
    // strands are finer than a pixel does the thinning show as partial cover. Placed on the
    // neutral head across the strands (v_rest's x and z; hair hangs along y there), so
    // neighbouring cards and layers end together instead of each in its own comb of teeth.
    float ends = (v_rest.y - u_end_height) / u_end_fade;
    if (ends < 1.0) {
        vec3 across = v_rest * vec3(1.0, 0.02, 1.0);
        float clump_end = lattice_noise3(across * 16.0 + 3.0);              // clumps ~6 mm across
        vec3 sp = across * 140.0 + 9.0;                                     // strands < 1 mm across
        float strand_detail = clamp(2.0 - 1.4 * length(fwidth(sp)), 0.0, 1.0);
        float strand_end = mix(0.5, lattice_noise3(sp), strand_detail);
        // (inner layers end a little higher, behind the outer ones, so they never show below them)
        float end_at = 0.3 + 0.3 * clump_end + 0.06 * (strand_end - 0.5)
                     + 0.08 * (1.0 - smoothstep(0.3, 0.9, v_depth));
        float thinning = clamp((ends - end_at) / 0.12, 0.0, 1.0);           // over ~7 mm to the tips
        float rank = lattice_noise3(sp * vec3(1.3, 1.0, 1.3) + 21.0);
        // (value noise gathers about its mean: the ramp spans its range, and nothing is left past the ends)
        float tips = mix(thinning, smoothstep(rank - 0.06, rank + 0.06, 1.2 * thinning - 0.1), strand_detail);
        alpha *= tips * step(1e-4, thinning);
    }
    float px_full = px;
    if (u_along_v > 0.5) px = mix(0.5, px, 0.8);
    // Locks: strands gather into locks a few millimetres across and several long, placed on the
    // neutral head along the strands (so they run on across the cards, as px does); the narrow
    // gaps between them lie in their neighbours' shade and their crowns catch the light, so a
    // head of straight hair shows depth between locks rather than one smooth sheet (mei's black
    // bob read as a flat sheet, blind review, session 21). Faded to its mean where finer than a pixel.
    vec3 lock_p = v_rest * LOCK_CELLS_PER_DM;
    // Where the strands run down and out from the crown (the hanging lengths, a short style's
    // mass) the locks follow that flow (flow_lock_coordinate); where they turn from it (a fringe, hair
    // brushed sideways from a parting), a smear along their own direction.
    vec3 lock_nv = normalize(v_rest - volume_axis_point(v_rest, u_hair_apex_rest));
    vec3 lock_meridian = cross(lock_nv, normalize(cross(vec3(0.0, 1.0, 0.0), lock_nv) + vec3(1e-5, 0.0, 0.0)));
    float lock_flow = smoothstep(0.6, 0.85, abs(dot(lock_meridian, along_rest)));
    // Hair whose texture runs along v (long01, the bobs) hangs down and out from the crown as a
    // whole: its locks follow that flow everywhere. Switched by each card's own tangent (the crown's
    // cards lie every way), the locks and their dark partings changed pattern at every card's
    // edge and drew the crown's cards as dark rectangles (ava's and mei's "helmet hair", blind
    // review session 25, 26 of 26 images).
    lock_flow = max(lock_flow, u_along_v);
    vec3 flow_lock_p = flow_lock_coordinate(v_rest);
    float smear_fade = clamp(2.5 - 1.6 * length(fwidth(lock_p)), 0.0, 1.0);
    float flow_fade = clamp(2.5 - 1.6 * length(fwidth(flow_lock_p)), 0.0, 1.0);
    float lock = 0.5;
    if (lock_flow < 0.999)
        lock = mix(0.5, smeared_noise(lock_p + 19.0, 1.6 * along_rest), smear_fade);
    if (lock_flow > 0.001)
        lock = mix(lock, mix(0.5, lattice_noise3(flow_lock_p + 19.0), flow_fade), lock_flow);
    // The partings between locks open and close along their length (a lock crosses over its
    // neighbour, strands bridge the gap), a centimetre or two at a time: unbroken, they ran from
    // the crown to the ends as ruled lines.
    float parting_open = smoothstep(0.3, 0.62, lattice_noise3(flow_lock_p * vec3(1.3, 4.0, 1.3) + 53.0));
    // (long hair's locks show shallower gaps than a short style's: at full depth they drew
    // bands across the crown)
    lock = clamp(0.5 + mix(1.6, 0.8, u_along_v) * (lock - 0.5), 0.0, 1.0);
#endif
    // The hair's outline: where the volume turns away from the eye, its outer strands stand
    // apart, so the outline breaks into strands and clumps with the background between them
    // instead of ending in the cards' cut edge. Inside the mass the cards' own alpha rules.
    float outline = 1.0 - smoothstep(0.02, 0.28, dot(n, v));
    float strand_mask = smoothstep(0.3, 0.7, 0.6 * px + 0.4 * clump);
    // A card's own outline frays the same way: strands end at different lengths across the
    // last triangle before the cut edge, so layers overlap as strand tips, not as steps.
    // Coily hair's textures draw their own loose curls at every edge, and its cap is the
    // dense base the tufts grow from: neither frays.
    float rag = 0.45 * px + 0.3 * mid + 0.25 * clump;
    float fray = outline * (1.0 - strand_mask) * 0.9;
    fray = 1.0 - (1.0 - fray) * (1.0 - smoothstep(0.3, 0.75, v_edge + 0.9 * (0.5 - rag)));
    alpha *= 1.0 - fray * (1.0 - u_coil);
    // A card seen edge-on at the outline (its own face, not the volume's, turned away) is a
    // line a pixel wide standing off the mass: it fades, so the outline does not draw strokes
    // around the head.
    vec3 card_normal = cross(dFdx(v_pos), dFdy(v_pos));
    float face_on = abs(dot(card_normal, v)) / max(length(card_normal), 1e-12);
    alpha *= mix(1.0, smoothstep(0.06, 0.3, face_on), smoothstep(0.3, 0.8, outline) * (1.0 - u_coil));
#ifdef COILY
    {
        float inside_mm = coily_inside_outline_mm(v_pos, v);
        float bump = coily_clumps(coil_place(v_rest));
        // Coily hair is a dense mass: the texture's tufts and the holes between them are filled
        // (each hole showed the darker cards under it as a hard-edged fragment: "voxel-like",
        // blind review session 24).
        float fill = clamp(0.5 + (tex.a - 0.3) / max(fwidth(tex.a), 0.002), 0.0, 1.0);
        // Its outline: rounded clumps of coils standing up to COILY_BUMP_MM out of the mass
        // (the cards are cut where they reach further out than the clump there), each solid
        // and anti-aliased over a pixel: no translucent halo, no speckle.
        // Low on the sides, where the mass ends over the ears, the cards' outline is the hair's
        // (the cut moves out of the way rather than fading: a fade drew grey translucent tufts).
        float below_dome = dome_base(u_hair_apex) - v_pos.y;   // dm
        float out_mm = inside_mm - COILY_BUMP_MM * (1.0 - bump) + 30.0 * smoothstep(0.75, 0.9, below_dome);
        float edge = clamp(0.5 + out_mm / max(fwidth(out_mm), 0.05), 0.0, 1.0);
        // A card seen edge-on is a line (standing off the mass at the outline, or beside the
        // ears below it): dropped whole; the mass behind it is shaded alike.
        alpha = mix(alpha, fill * edge * step(0.12, face_on), u_coil);
    }
#endif
    // Over a thinning hairline (v_cover < 1, see facsim/head/scalp.py) the cards break up into
    // strands and clumps, fewer the thinner the cover, so they fade into the scalp's fine hairs.
#ifdef COILY
    // Coily hair thins in whole clumps of coils (coily_clumps), each solid, with skin between
    // them: curls finer than a pixel thinned it into a grey translucent film (the tufts over
    // the ears).
    // (and the clumps' edges break into single coils, so the hairline ends in short coils; not
    // toward the outline, where coils a pixel across would speckle it: the outline is the clumps')
    float thin_at = coily_clumps(coil_place(v_rest))
                  - 0.3 * coil_detail * smoothstep(0.2, 0.55, dot(n, v)) * (coil.w - 0.6);
    float thin_by = 1.3 * v_cover - 0.15 - thin_at;
    alpha *= clamp(0.5 + thin_by / max(fwidth(thin_by), 0.002), 0.0, 1.0);
#else
    float thin_at = rag;
    alpha *= smoothstep(thin_at - 0.2, thin_at + 0.2, 1.3 * v_cover - 0.15);
#endif
#endif
#ifdef PASS_OPAQUE
    if (alpha < ALPHA_CUTOFF) discard;
    alpha = 1.0;
#else
    if (alpha >= ALPHA_CUTOFF || alpha < 0.02) discard;
    alpha = alpha / ALPHA_CUTOFF;  // the fringe fades out fully at its edge
#endif
#endif
#ifndef KIND_HAIR
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_cam_pos - v_pos);
    if (dot(n, v) < 0.0) n = -n;   // hair normals come from the volume and face outward already
#endif
    vec3 albedo = u_color * (0.6 + 0.8 * tex.r);

#ifdef KIND_HAIR
    vec3 t = normalize(v_tangent);
#ifdef PASS_OPAQUE
    vec2 sp = v_uv * vec2(420.0, 5.0) + 2.0 * phase;
    float fine = mix(0.5, value_noise(sp, 0), along_v * clamp(1.8 - 1.6 * fwidth(sp.x), 0.0, 1.0));
#else
    float fine = 0.5;   // the thin fringe: too sparse for the finest breakup to show
#endif
    // Strand-scale brightness: the texture's own strands (tex.r: its painted light removed,
    // see shade_texture) and three scales of procedural strands, so neighbouring strands and
    // clumps differ the way real hair does, the same on every card.
    // (The texture's strands and the widest scale stop at each card's edge: on long01's crown,
    // at full strength they drew the rows of cards, so they keep less weight.)
    mp += phase;
    mid = mix(0.5, value_noise(mp, 0), along_v * clamp(2.0 - 1.4 * fwidth(mp.x), 0.0, 1.0));
    cp += 0.5 * phase;
    clump = mix(0.5, value_noise(cp, 0), along_v * clamp(2.0 - 1.5 * fwidth(cp.x), 0.0, 1.0));
#ifndef COILY
    // Long hair's crown: the cards' own texture and UV clumps run along each card (sideways
    // there, a card to a row) and stop at its edge: they drew the rows as wood grain and the
    // cards as blocks under strands and locks that follow the flow. They keep a little say there
    // (the crown: over the hair volume's dome, placed on the head, not by each card's tangent);
    // the hanging lengths' cards run down with their strands and keep theirs.
    {
        float crown = smoothstep(-0.3, 0.1, v_rest.y - dome_base(u_hair_apex_rest));
        float card_say = 1.0 - 0.75 * u_along_v * crown;
        tex.r = mix(0.5, tex.r, card_say);
        fine = mix(0.5, fine, card_say);
        mid = mix(0.5, mid, card_say);
        clump = mix(0.5, clump, card_say);
    }
#endif
    // (px: strands and clumps a couple of pixels across, so the breakup shows at any size.)
    float strand = (0.62 + 0.76 * tex.r) * (0.7 + 0.6 * fine) * (0.6 + 0.8 * px) * (0.8 + 0.4 * mid)
                 * (0.9 + 0.2 * clump);
#ifdef COILY
    float crown;   // coily clumps: 0 in a crevice ... 1 on a crown
    {
        // Coily hair at stimulus sizes: a dense mass whose clumps of coils (3-8 mm, coily_clumps)
        // show as a fine, even, low-contrast texture, each clump's crown a little lighter than
        // the hollows around it, with single coils (~1.5 mm) faintly over it where a pixel
        // resolves them. (A network of dark crevices read as cracked leather; per-pixel curls
        // and the texture's mirrored tufts as speckle.)
        vec3 q = coil_place(v_rest);
        // (toward the outline the eye grazes the mass, along which cards lie at different
        // directions from the axis: there the texture, which would jump from card to card in
        // stripes, fades to its mean; the outline's own clumps break it up)
        float seen = smoothstep(0.2, 0.55, dot(n, v));
        float bump = mix(0.5, coily_clumps(q), seen);
        float coils = mix(0.5, coil_id, coil_detail);
        crown = smoothstep(0.3, 0.7, bump);
        // (light hair scatters light into the hollows: grey afros' at full depth drew them as
        // blotchy camouflage)
        float light = sqrt(clamp(dot(u_color, LUMINANCE), 0.0, 1.0));
        // Each coil: its top and its side toward the key lighter, the crevices round it darker.
        float coil_key = clamp(dot(coil.xyz - n, u_key_dir) + 0.5, 0.0, 1.0);
        // (light hair scatters light into the crevices: grey coils at full depth read as gravel)
        float coil_shade = mix(1.0, mix(mix(0.45, 0.7, light), 1.1, coil.w) * (0.7 + 0.6 * coil_key)
                                  * (0.85 + 0.3 * coil_id) * coil_hairs, coil_detail * mix(1.0, 0.7, light));
        strand = mix(strand, mix(mix(0.55, 0.75, light), mix(1.15, 1.05, light), crown) * coil_shade, u_coil);
        // Greying coily hair mixes white, grey and dark coils (placed on the head, not in the
        // cards' mirrored UVs), finer than its clumps: clumps of white and dark drew grey afros
        // as blotchy cloud or cauliflower (blind review session 20).
        float white = clamp(u_grey + 0.3 * (coils - 0.5) + 0.15 * (bump - 0.5), 0.0, 1.0);
        albedo = (u_grey > 0.0 ? mix(u_pigment, u_white, white) : u_color) * strand;
    }
#else
    vec3 clump_colour;
    // (long hair: greying clumps along the flow too; in the cards' UVs each card of the crown
    // was its own patch of white or grey)
    if (u_grey > 0.0 && u_along_v > 0.5) {
        vec3 q = flow_lock_p * vec3(2.0, 4.0, 2.0) + 29.0;   // ~3 mm across, several cm along
        clump_colour = grey_clump_colour(lattice_noise3(q), clamp(0.5 * length(fwidth(q)) - 0.25, 0.0, 1.0));
    } else {
        clump_colour = hair_colour(v_uv * vec2(45.0, 1.2) + 7.0 + 0.5 * phase);
    }
    albedo = clump_colour * strand;
    // Greying hair: white, grey and dark strands side by side at the pixel scale too (the
    // clump-scale mix above fades to one flat grey at stimulus sizes).
    if (u_grey > 0.0)
        albedo = mix(albedo, mix(u_pigment, u_white, clamp(u_grey + 0.45 * (px_full - 0.5), 0.0, 1.0)) * strand, 0.7);
    // Strands differ in pigment, not only in brightness: lighter ones warmer (less eumelanin:
    // pheomelanin's red-gold shows), darker ones cooler, clump by clump and strand by strand
    // (white strands have none to vary); and long hair's tips, older and weathered, are a
    // little lighter than the lengths above them.
    float pigment_shift = (0.6 * (mid - 0.5) + 0.5 * (px_full - 0.5)) * (1.0 - u_grey);
    albedo *= (vec3(1.0) + pigment_shift * vec3(0.4, 0.1, -0.3)) * mix(1.18, 1.0, smoothstep(0.25, 1.0, ends));
#endif
    // Depth in the volume: layers near the scalp lie under the outer ones and get little
    // light (roots and the under-layers darker), the gaps between clumps are darker still.
    // Light hair (blond, grey) scatters light on through the strands, so its inner layers
    // darken much less than dark hair's (the multiple scattering of Marschner's model).
    // Coily hair is denser: its inner curls stay dark whatever the colour.
    float light_hair = sqrt(clamp(dot(u_color, LUMINANCE), 0.0, 1.0)) * (1.0 - 0.6 * u_coil);
#if defined(USE_SHADOW) && defined(COILY)
    float key_reach = coily_key_visibility(v_pos, n);
#elif defined(USE_SHADOW)
    // The key's cast shadow: the mass's own (light hair lets it further in) and the head's.
    float key_reach = hair_key_visibility(v_pos, n, mix(3.0, 7.0, light_hair));
#else
    float key_reach = 1.0;
#endif
    // the parting between two locks running down the flow (a narrow crevice: shade, little highlight)
    float parting = smoothstep(0.7, 1.0, lock_flow) * lock_gap(lock) * parting_open;
    float layer = smoothstep(0.0, 0.95, v_depth);
    // (light hair's under-layers and gaps kept 0.7 and 0.85 of the light: george's and
    // margaret's grey read as a flat pale helmet without the depth a photograph shows between
    // locks; it still scatters light further in than dark hair does)
    float self_shadow = mix(mix(0.3, 0.58, light_hair), 1.0, layer * layer * (1.5 - 0.5 * layer))
                      * mix(mix(0.8, 0.9, light_hair), 1.0, clump) * mix(0.8, 1.0, mid)
    // and the narrow gaps between clumps are in their neighbours' shade: light and dark
    // alternate across the mass at the scale of clumps, not one smooth shell.
                      * mix(mix(0.74, 0.8, light_hair), 1.0, smoothstep(0.02, 0.32, px))
                      * mix(mix(LOCK_GAP_DARK, LOCK_GAP_LIGHT, light_hair), 1.0, smoothstep(0.15, 0.6, lock))
    // and the parting between two locks running down the flow is a narrow dark crevice
                      * (1.0 - parting * mix(0.6, 0.4, light_hair));
    float jitter = 0.22 * (tex.r - 0.5) + 0.12 * (fine - 0.5) + 0.18 * (mid - 0.5) + 0.1 * (clump - 0.5)
                 + 0.25 * (px - 0.5);
    // Key light: strand diffuse blended with a squared half-Lambert, which keeps the volume
    // readable without the flat look of a plain wrap.
    float kl = clamp(dot(n, u_key_dir) * 0.5 + 0.5, 0.0, 1.0);
    float dk = mix(strand_diffuse(t, u_key_dir), 1.0, 0.3 + 0.7 * u_coil) * kl * kl * 1.25;
    float df = clamp(dot(n, u_fill_dir) * 0.5 + 0.5, 0.0, 1.0);
    float dr = clamp(dot(n, u_rim_dir) * 0.5 + 0.5, 0.0, 1.0);
    vec3 lit = dk * key_reach * u_key_col + df * u_fill_col + dr * dr * u_rim_col * 0.8 + hemisphere(n) * 0.8;
#ifdef PASS_OPAQUE
    // Two Kajiya-Kay lobes of the key light, shifted along the normal (Marschner's R and TRT
    // as Scheuermann approximates them): a primary tinted a little toward the hair colour and
    // a hair-coloured, sparkly secondary. Each strand shifts them by its own jitter, so the
    // highlight band breaks into strands instead of drawing one smooth arc across the cards.
    // The blended fringe (thin wisps) skips them: they barely show there and cost time.
    vec3 h = normalize(u_key_dir + v);
    // Roots and under-layers lie in the outer strands' shadow: little highlight there, so the
    // two sides' different strand directions do not draw a line along a parting.
    // Where a card's corner tangents disagree (opposite signs), the interpolated tangent
    // shrinks and its direction means nothing: no highlight there (else a bright outline).
    // The lobes follow the hair's flow over the volume (down and out from the crown along its
    // surface, u_hair_apex) more than each card's own tangent: cards of a row are tilted and
    // turned each its own way, and with their tangents the highlight lit some cards and not
    // their neighbours, a patchwork of bright blocks on long01's crown (blind review, session
    // 20: "highlight patches"); along the flow it is one soft band across the head, broken
    // into strands by the jitter below, as a photographed head of hair shows it.
    vec3 from_apex = v_pos - u_hair_apex;
    vec3 flow = from_apex - dot(from_apex, n) * n;
    float flow_len = length(flow);
    vec3 ts = normalize(mix(t, flow / max(flow_len, 1e-6), HIGHLIGHT_FLOW * smoothstep(0.02, 0.1, flow_len)));
    // (the under-layers' gate is soft: per card, it drew the cards' outlines into the band)
    float gate = smoothstep(0.3, 0.6, kl) * mix(0.45, 1.0, smoothstep(0.2, 0.8, v_depth))
               * mix(smoothstep(0.6, 0.9, length(v_tangent)), 1.0, HIGHLIGHT_FLOW);
    float th1 = dot(normalize(ts + (0.06 + jitter) * n), h);
    float th2 = dot(normalize(ts + (-0.1 + jitter) * n), h);
    float s1 = max(1.0 - th1 * th1, 1e-6);   // sin^2
    float s2 = max(1.0 - th2 * th2, 1e-6);
    // (The finer UV scales fade to their means at stimulus sizes: they only modulate, and the
    // pixel-scale strands px break the band, so it reads at 512² as strands catching the light.)
    // (The texture's own strands and the cards' clumps keep only part of their say: they stop at
    // each card's edge, and at full strength they cut the band into the cards' shapes.)
    float strands = mix(0.55, 1.0, smoothstep(0.25, 0.7, fine) * smoothstep(0.2, 0.7, mid))
                  * mix(0.45, 1.0, smoothstep(0.3, 0.65, tex.r)) * mix(0.7, 1.0, clump) * smoothstep(0.3, 0.75, px) * 1.4
                  * mix(0.4, 1.6, lock) * (1.0 - 0.7 * parting);   // the locks' crowns catch the light, their gaps little
    float sparkle = smoothstep(0.45, 0.75, fine) * smoothstep(0.4, 0.7, mid) * smoothstep(0.4, 0.75, px);
    vec3 tint = hair_tint();
    // Light hair's own diffuse is bright already: a full-strength white lobe on it reads as
    // white streaks, so it takes less.
    gate *= mix(1.0, 0.55, light_hair);
    // A few sparse glints: single strands (a fraction of a millimetre across, a few long)
    // that catch the key light sharply where the primary lobe lies, as real hair glitters
    // here and there instead of shining evenly; faded out where they would be finer than a pixel.
    vec2 gp = v_uv * vec2(400.0, 9.0) + 13.0 + 3.0 * phase;
    float glint = smoothstep(0.86, 0.96, value_noise(gp, 0)) * along_v
                * clamp(1.6 - 1.2 * fwidth(gp.x), 0.0, 1.0);
    vec3 spec = u_key_col * gate * (0.24 * strands * tint * exp2(28.0 * log2(s1))
                                    + 0.55 * sparkle * u_color * exp2(10.0 * log2(s2))
                                    + 0.25 * glint * tint * exp2(40.0 * log2(s1)));
#else
    vec3 spec = vec3(0.0);
#endif
#ifdef COILY
    // (each coil's own glint where its dome faces halfway between the key and the eye, some
    // coils brighter than others and those on the clumps' crowns most: an even glint on every
    // coil drew a regular lattice of dots)
    float glint_at = max(dot(coil.xyz, normalize(u_key_dir + v)), 0.0);
    vec3 coil_glint = u_key_col * hair_tint() * 0.5 * exp2(24.0 * log2(max(glint_at, 1e-4)))
                    * coil_detail * (0.2 + 1.3 * coil_id * coil_id) * mix(0.3, 1.2, crown) * coil_hairs * coil_hairs;
    spec = mix(spec, coily_sheen(n, v, crown) + coil_glint, u_coil);
    self_shadow = mix(self_shadow, coily_self_shadow(n, v, crown, v_pos.y - dome_base(u_hair_apex)), u_coil);
#endif
    vec3 radiance = (albedo * lit + u_sheen * key_reach * spec) * self_shadow;
#else
    // Brows and lashes: fine dark hairs, softly lit, little sheen.
    float dk = clamp(dot(n, u_key_dir) * 0.5 + 0.5, 0.0, 1.0);
    vec3 lit = dk * u_key_col + u_fill_col + hemisphere(n);
    vec3 radiance = albedo * lit * 0.8;
#ifdef KIND_EYELASHES
    radiance *= mix(0.55, 0.9, v_depth);   // lashes: darkest in the dense line at their roots
#else
    radiance *= mix(1.0, 0.8 + 0.4 * stroke, stroke_detail);   // brow hairs differ one from the next
#endif
#endif
    f_color = vec4(finish(radiance).rgb, alpha);
}
#endif
