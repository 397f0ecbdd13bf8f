// Supersampling resolve: box-filter FACTOR x FACTOR texels of the large image into one pixel.
// Variants: FACTOR (int), UNPREMULTIPLY (transparent background: the box average of
// coverage-weighted colours is premultiplied; divide it back out).
uniform sampler2D u_image;
out vec4 f_color;

void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * FACTOR;
    vec4 sum = vec4(0.0);
    for (int j = 0; j < FACTOR; ++j)
        for (int i = 0; i < FACTOR; ++i)
            sum += texelFetch(u_image, base + ivec2(i, j), 0);
    vec4 c = sum / float(FACTOR * FACTOR);
#ifdef UNPREMULTIPLY
    c.rgb = c.a > 0.0 ? c.rgb / c.a : vec3(0.0);
#endif
    f_color = c;
}
