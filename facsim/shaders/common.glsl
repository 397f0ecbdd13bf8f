// Shared by the face fragment shader variants: colour space, noise, and the light rig.
// render.py prepends "#version 330 core" and the variant's #defines, and inlines this file
// where face.frag.glsl includes it (render.py does the include, not the GL driver).

const float PI = 3.14159265;

// Light rig, world space. Directions point FROM the surface TOWARD the light; colours are
// linear RGB with the intensity folded in (Renderer builds them from a Lighting and the camera).
uniform vec3 u_cam_pos;
uniform vec3 u_key_dir;
uniform vec3 u_key_col;
uniform vec3 u_fill_dir;
uniform vec3 u_fill_col;
uniform vec3 u_rim_dir;
uniform vec3 u_rim_col;
uniform vec3 u_sky_col;     // hemispheric ambient, world +Y
uniform vec3 u_ground_col;  // hemispheric ambient, world -Y
uniform float u_exposure;

// ---- colour space -----------------------------------------------------------------------
vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// Identity up to 0.8, then a soft shoulder that reaches 1 asymptotically: highlights roll off
// instead of clipping to flat white patches.
vec3 tonemap(vec3 c) {
    vec3 shoulder = 0.8 + 0.2 * (1.0 - exp(-(c - 0.8) / 0.2));
    return mix(c, shoulder, step(0.8, c));
}

// ---- hashing and noise (deterministic: the same inputs give the same image) ---------------
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float hash2(ivec2 p) {
    uint h = pcg_hash(uint(p.x) * 1597334677u ^ pcg_hash(uint(p.y)));
    return float(h) * (1.0 / 4294967295.0);
}

// Value noise in [0, 1]; x wraps with integer period `period_x` (0 = no wrap).
float value_noise(vec2 p, int period_x) {
    vec2 i = floor(p);
    vec2 f = p - i;
    vec2 u = f * f * (3.0 - 2.0 * f);
    ivec2 i0 = ivec2(i);
    ivec2 i1 = i0 + 1;
    if (period_x > 0) {
        i0.x = ((i0.x % period_x) + period_x) % period_x;
        i1.x = ((i1.x % period_x) + period_x) % period_x;
    }
    float a = hash2(ivec2(i0.x, i0.y));
    float b = hash2(ivec2(i1.x, i0.y));
    float c = hash2(ivec2(i0.x, i1.y));
    float d = hash2(ivec2(i1.x, i1.y));
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// ---- lighting helpers ---------------------------------------------------------------------
vec3 hemisphere(vec3 n) {
    return mix(u_ground_col, u_sky_col, 0.5 + 0.5 * n.y);
}

// Energy-normalised Blinn-Phong lobe times N.L.
float blinn(vec3 n, vec3 l, vec3 v, float shininess) {
    vec3 h = normalize(l + v);
    float ndl = max(dot(n, l), 0.0);
    return (shininess + 8.0) / (8.0 * PI) * pow(max(dot(n, h), 0.0), shininess) * ndl;
}

float schlick(float f0, float cos_theta) {
    float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * m2 * m2 * m;
}

// Linear radiance -> display sRGB with a 1/255 deterministic dither against banding.
vec4 finish(vec3 radiance) {
    vec3 c = srgb_encode(tonemap(radiance * u_exposure));
    float d = hash2(ivec2(gl_FragCoord.xy)) - 0.5;
    return vec4(c + d / 255.0, 1.0);
}
