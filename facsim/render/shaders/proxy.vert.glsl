// Proxy (hair, eyebrow, eyelash card) vertex shader; see facsim/render/proxies.py.
in vec3 in_pos;
in vec3 in_normal;
in vec3 in_tangent;   // strand direction (dP/dv)
in float in_depth;    // hair: 0 under other layers .. 1 in the open
in float in_edge;     // hair: 1 on a card's outline, 0 inside
in vec2 in_uv;
in float in_cover;
in vec3 in_rest;      // hair: the vertex on the neutral face (dm), where coily hair's curls lie    // hair: the scalp's hair density under the vertex (1 full ... 0 bare)

uniform mat4 u_view_proj;

out vec3 v_pos;
out vec3 v_normal;
out vec3 v_tangent;
out float v_depth;
out float v_edge;
out vec2 v_uv;
out float v_cover;
out vec3 v_rest;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_tangent = in_tangent;
    v_depth = in_depth;
    v_edge = in_edge;
    v_uv = in_uv;
    v_cover = in_cover;
    v_rest = in_rest;
    gl_Position = u_view_proj * vec4(in_pos, 1.0);
}
