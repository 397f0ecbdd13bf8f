// Proxy (hair, eyebrow, eyelash card) vertex shader; see facsim/render/proxies.py.
in vec3 in_pos;
in vec3 in_normal;
in vec3 in_tangent;   // strand direction (dP/dv)
in float in_depth;    // hair: 0 under other layers .. 1 in the open
in float in_edge;     // hair: 1 on a card's outline, 0 inside
in vec2 in_uv;
in float in_cover;
in vec3 in_rest;      // hair: the vertex on the neutral face (dm), where coily hair's curls lie
in vec3 in_rest_tangent;  // hair: the strand direction there
// in_cover: hair: the scalp's hair density under the vertex (1 full ... 0 bare)
// Wisps (loose strands): in_pos is a point on the strand, in_tangent the strand's direction,
// in_depth 0 at the root ... 1 at the tip, in_edge the side of the ribbon (-1, 1).

uniform mat4 u_view_proj;
#ifdef KIND_WISPS
uniform vec3 u_cam_pos;
uniform vec2 u_viewport;       // frame buffer size, pixels
uniform float u_strand_width;  // dm at the root
#endif

out vec3 v_pos;
out vec3 v_normal;
out vec3 v_tangent;
out float v_depth;
out float v_edge;
out vec2 v_uv;
out float v_cover;
out vec3 v_rest;
out vec3 v_rest_tangent;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_tangent = in_tangent;
    v_depth = in_depth;
    v_edge = in_edge;
    v_uv = in_uv;
    v_cover = in_cover;
    v_rest = in_rest;
    v_rest_tangent = in_rest_tangent;
#ifdef KIND_WISPS
    // A ribbon across the strand, turned toward the camera, tapering to a tenth at the tip.
    // Where it would be narrower than a pixel it is drawn a pixel wide and fainter (v_cover:
    // the share of the drawn width the strand covers), so thin strands neither vanish
    // between samples nor flicker.
    vec3 side = cross(normalize(in_tangent), normalize(u_cam_pos - in_pos));
    side /= max(length(side), 1e-4);
    vec4 c0 = u_view_proj * vec4(in_pos, 1.0);
    vec4 c1 = u_view_proj * vec4(in_pos + 0.01 * side, 1.0);
    float px_per_dm = length((c1.xy / c1.w - c0.xy / c0.w) * 0.5 * u_viewport) / 0.01;
    float width = u_strand_width * mix(1.0, 0.1, in_depth);
    float drawn = max(width, 1.2 / max(px_per_dm, 1e-3));
    v_cover = width / drawn;
    v_pos = in_pos + (0.5 * drawn * in_edge) * side;
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
#else
    gl_Position = u_view_proj * vec4(in_pos, 1.0);
#endif
}
