// The key light's cast shadow (facsim/render/shadows.py: a depth map drawn from the key).
// Included by face.frag.glsl after common.glsl. Variants that receive shadows (USE_SHADOW)
// set key_shadow in main(); the rest keep it at 1 (the mouth's parts get their light from
// facsim.head.mouth per frame instead).

// How much of the key light reaches this fragment, per channel (skin: wider in red).
vec3 key_shadow = vec3(1.0);

#ifdef USE_SHADOW
uniform sampler2DShadow u_shadow;     // depth from the key, compared in hardware (bilinear)
uniform sampler2D u_shadow_opacity;   // R: how much of the key the nearest caster stops (hair < 1)
uniform mat4 u_shadow_matrix;         // world -> map coordinates in [0, 1]^3 (z: depth, 0 at the light)
uniform float u_shadow_size;          // map side, texels
uniform float u_shadow_texel;         // dm per texel
uniform float u_shadow_depth_range;   // dm across the map's depth 0..1

// The receiver is pushed off its surface along the normal, by more where the key grazes it:
// the filter compares over a few texels of a tilted surface, and a point at its own depth
// would shade itself (acne). Half a texel more in depth covers the map's own quantisation.
const float SHADOW_NORMAL_OFFSET = 2.0;   // texels at grazing light (plus one facing it)
const float SHADOW_DEPTH_BIAS = 0.5;      // texels

float shadow_tap(vec2 base, float u, float v, float depth) {
    return texture(u_shadow, vec3(base + vec2(u, v) / u_shadow_size, depth));
}

// Visibility of the key at p (world) with normal n: a 3x3-texel tent filter in four bilinear
// comparisons (Castano's optimised PCF, as in The Witness), a smooth penumbra about three
// texels (~8 mm) wide. Outside the map (nothing casts there) the key is unobstructed.
float key_visibility(vec3 p, vec3 n) {
    float ndl = clamp(dot(n, u_key_dir), -1.0, 1.0);
    float graze = sqrt(1.0 - ndl * ndl);
    vec3 q = p + n * (u_shadow_texel * (1.0 + SHADOW_NORMAL_OFFSET * graze));
    vec3 c = (u_shadow_matrix * vec4(q, 1.0)).xyz;
    float depth = c.z - SHADOW_DEPTH_BIAS * u_shadow_texel / u_shadow_depth_range;
    vec2 uv = c.xy * u_shadow_size;
    vec2 base = floor(uv + 0.5);
    vec2 st = uv + 0.5 - base;
    base = (base - 0.5) / u_shadow_size;
    vec2 w0 = 3.0 - 2.0 * st, w1 = 1.0 + 2.0 * st;
    vec2 o0 = (2.0 - st) / w0 - 1.0, o1 = st / w1 + 1.0;
    float sum = w0.x * w0.y * shadow_tap(base, o0.x, o0.y, depth) + w1.x * w0.y * shadow_tap(base, o1.x, o0.y, depth)
              + w0.x * w1.y * shadow_tap(base, o0.x, o1.y, depth) + w1.x * w1.y * shadow_tap(base, o1.x, o1.y, depth);
    float inside = step(0.0, c.x) * step(c.x, 1.0) * step(0.0, c.y) * step(c.y, 1.0) * step(c.z, 1.0);
    float opacity = texture(u_shadow_opacity, c.xy).r;
    return 1.0 - (1.0 - sum * (1.0 / 16.0)) * opacity * inside;
}
#endif

// Skin: light entering on the lit side of a shadow's edge comes out a few millimetres into the
// shade, its green and blue absorbed on the way: the penumbra is wider in red and narrower in
// blue, a warm band along the edge (photographs of faces; a grey edge reads as paint on
// plaster). `scatter` 0..1: how much (less under hair, and in melanin-rich skin).
#if defined(USE_SHADOW) && defined(REGION_SKIN)
void skin_shadow_edge(float scatter) {
    float s = key_shadow.g;
    key_shadow = clamp(s + vec3(0.4, 0.0, -0.12) * (scatter * s * (1.0 - s)), 0.0, 1.0);
}
#else
void skin_shadow_edge(float scatter) {}
#endif
