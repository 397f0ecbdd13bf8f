// Fast approximate anti-aliasing (after T. Lottes' FXAA): one shaded sample per pixel,
// then edges found by luma contrast are blurred along their direction. About a third
// of 4x MSAA's cost on llvmpipe, which shades every sample; used for video frames.
// Variant: UNPREMULTIPLY (transparent background: colours over alpha 0 are black, so
// blends are premultiplied; divide it back out).
uniform sampler2D u_image;
out vec4 f_color;

const float EDGE_MIN = 1.0 / 32.0;   // ignore contrast below this (flat regions)
const float EDGE_REL = 1.0 / 8.0;    // ... or below this fraction of the local maximum
const float SPAN_MAX = 8.0;          // longest blur along an edge, in pixels

float luma(vec4 c) { return dot(c.rgb, vec3(0.299, 0.587, 0.114)); }

void main() {
    vec2 px = 1.0 / vec2(textureSize(u_image, 0));
    vec2 uv = gl_FragCoord.xy * px;
    vec4 centre = texture(u_image, uv);
    float nw = luma(texture(u_image, uv + vec2(-0.5, -0.5) * px));
    float ne = luma(texture(u_image, uv + vec2(0.5, -0.5) * px));
    float sw = luma(texture(u_image, uv + vec2(-0.5, 0.5) * px));
    float se = luma(texture(u_image, uv + vec2(0.5, 0.5) * px));
    float m = luma(centre);
    float lo = min(m, min(min(nw, ne), min(sw, se)));
    float hi = max(m, max(max(nw, ne), max(sw, se)));
    vec4 c = centre;
    if (hi - lo >= max(EDGE_MIN, hi * EDGE_REL)) {
        vec2 dir = vec2(-((nw + ne) - (sw + se)), (nw + sw) - (ne + se));
        float reduce = max((nw + ne + sw + se) * 0.03125, 1.0 / 128.0);
        dir = clamp(dir / (min(abs(dir.x), abs(dir.y)) + reduce), -SPAN_MAX, SPAN_MAX) * px;
        vec4 a = 0.5 * (texture(u_image, uv - dir / 6.0) + texture(u_image, uv + dir / 6.0));
        vec4 b = 0.5 * a + 0.25 * (texture(u_image, uv - dir * 0.5) + texture(u_image, uv + dir * 0.5));
        float lb = luma(b);
        c = (lb < lo || lb > hi) ? a : b;
    }
#ifdef UNPREMULTIPLY
    c = c.a >= 1.0 / 255.0 ? vec4(c.rgb / c.a, c.a) : vec4(0.0);  // what stores as alpha 0 is empty
#endif
    f_color = c;
}
