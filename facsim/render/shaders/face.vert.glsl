// Face vertex shader. Variants (#defines from render.py): USE_UV, USE_EYE, USE_WRINKLE, USE_LASH,
// USE_LIDS (eyeballs: degrees below the upper lid's margin and above the lower's, carried in
// the wrinkle and crease slots).
// Regions that ignore occlusion let the compiler drop it (render.py tolerates that).
in vec3 in_pos;      // world position (decimetres)
in vec3 in_normal;   // smooth world normal, computed on geometry vertices in numpy
in float in_occlusion;  // ambient visibility 0..1 (1 = open sky), per geometry vertex
#if defined(USE_WRINKLE) || defined(USE_LASH) || defined(USE_LIDS)
in float in_wrinkle;  // skin: wrinkle amount; lashes: root-to-tip coordinate; eyeball: below the upper lid
#endif
#ifdef USE_LIDS
in float in_crease;   // eyeball: above the lower lid
out vec2 v_lids;
#endif
#ifdef USE_WRINKLE
in float in_crease;   // position across the creases in crease spacings, see render.crease_phase
out float v_wrinkle;
out float v_crease;
#endif
#ifdef USE_LASH
out float v_lash;
#endif
#if defined(REGION_SKIN) || defined(REGION_TONGUE)
in vec3 in_scatter_normal;  // the normal averaged over a few millimetres (subsurface light sees it)
out vec3 v_scatter_normal;
in float in_curvature;      // signed 1 / radius of the surface (dm^-1), render.geometry.surface_curvature
out float v_curvature;
#endif
#ifdef USE_UV
in vec2 in_uv;
out vec2 v_uv;
#endif
#ifdef USE_EYE
in vec3 in_eye;      // direction from the eye centre in the eye's own frame, +Z = gaze
out vec3 v_eye;
#endif

uniform mat4 u_view_proj;

out vec3 v_pos;
out vec3 v_normal;
out float v_occlusion;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_occlusion = in_occlusion;
#if defined(REGION_SKIN) || defined(REGION_TONGUE)
    v_scatter_normal = in_scatter_normal;
    v_curvature = in_curvature;
#endif
#ifdef USE_WRINKLE
    v_wrinkle = in_wrinkle;
    v_crease = in_crease;
#endif
#ifdef USE_LASH
    v_lash = in_wrinkle;
#endif
#ifdef USE_LIDS
    v_lids = vec2(in_wrinkle, in_crease);
#endif
#ifdef USE_UV
    v_uv = in_uv;
#endif
#ifdef USE_EYE
    v_eye = in_eye;
#endif
    gl_Position = u_view_proj * vec4(in_pos, 1.0);
}
