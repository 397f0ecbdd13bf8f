// Shared by the face fragment shader variants: colour space, noise, and the light rig.
// render.py prepends "#version 330 core" and the variant's #defines, and inlines this file
// where face.frag.glsl includes it (render.py does the include, not the GL driver).

const float PI = 3.14159265;
const vec3 LUMINANCE = vec3(0.2126, 0.7152, 0.0722);   // Rec. 709: linear RGB -> luminance

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
// Linear -> sRGB with square roots instead of pow (transcendentals are slow on llvmpipe);
// within 0.6/255 of the exact curve above 0.0031, and exact (linear segment) below it.
vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    vec3 s1 = sqrt(c);
    vec3 s2 = sqrt(s1);
    vec3 s3 = sqrt(s2);
    vec3 curve = 0.662002687 * s1 + 0.684122060 * s2 - 0.323583601 * s3 - 0.0225411470 * c;
    return mix(12.92 * c, curve, step(0.0031308, c));
}

// Filmic curve: a slight toe (deep shadows a little deeper, for contrast), near-identity
// through the mid-tones (a colour lit by the key shows as the user set it), then an
// exponential shoulder from 0.55 that keeps gradation in lit pale skin and rolls
// highlights off toward white instead of clipping them to flat patches. Continuous in
// value and slope at the joint.
const float SHOULDER = 0.55;
vec3 tonemap(vec3 c) {
    c = max(c, 0.0);
    c = c * (c + 0.012) / (c + 0.02);
    vec3 over = max(c - SHOULDER, 0.0) / (1.0 - SHOULDER);
    return min(c, SHOULDER) + (1.0 - SHOULDER) * (1.0 - exp2(-1.442695 * over));
}

// ---- hashing and noise (deterministic: the same inputs give the same image) ---------------
// A cheap integer hash of a lattice point to [0, 1) (a multiply-xorshift mix; ample for
// visual noise and much cheaper than PCG on llvmpipe, where the fragment shader is the cost).
float hash2(ivec2 p) {
    uint h = uint(p.x) * 0x8da6b343u + uint(p.y) * 0xd8163841u;
    h ^= h >> 15u;
    h *= 0x2c1b3c6du;
    h ^= h >> 12u;
    return float(h >> 8u) * (1.0 / 16777216.0);
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

// value_noise (no wrap) with its gradient: (value, d/dp.x, d/dp.y). A bump's slope taken from
// this per pixel, rather than from screen derivatives of the value (one per 2x2-pixel quad), does
// not break into 2x2 blocks.
vec3 value_noise_grad(vec2 p) {
    vec2 i = floor(p);
    vec2 f = p - i;
    vec2 u = f * f * (3.0 - 2.0 * f);
    vec2 du = 6.0 * f * (1.0 - f);
    ivec2 i0 = ivec2(i);
    float a = hash2(i0);
    float b = hash2(i0 + ivec2(1, 0));
    float c = hash2(i0 + ivec2(0, 1));
    float d = hash2(i0 + ivec2(1, 1));
    float k = a - b - c + d;
    return vec3(mix(mix(a, b, u.x), mix(c, d, u.x), u.y),
                du.x * (b - a + k * u.y), du.y * (c - a + k * u.x));
}

// The slope of smoothstep(e0, e1, x) in x: a bump shaped by smoothstep keeps its slope per pixel.
float smoothstep_slope(float e0, float e1, float x) {
    float t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return 6.0 * t * (1.0 - t) / (e1 - e0);
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
