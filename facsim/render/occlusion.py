"""Ambient occlusion baked on the GPU: per-vertex visibility of the sky, from depth maps.

The renderer casts no shadows; :func:`bake_occlusion` gives the per-vertex ambient
visibility to pass to :meth:`Renderer.render(occlusion=...) <facsim.render.Renderer.render>`,
which darkens sockets and creases with it. It draws the mesh as depth maps in the shared
context of :mod:`facsim.render.gl`.
"""
from __future__ import annotations

import numpy as np

from facsim.render.geometry import sphere_directions, vertex_normals
from facsim.render.gl import compile_program, gl_context
from facsim.head.mesh import RenderTopology

_DEPTH_VS = """
in vec3 in_pos;
uniform mat4 u_view_proj;
uniform vec3 u_dir;     // toward the viewer (the sky direction being tested)
out float v_depth;
void main() {
    v_depth = -dot(in_pos, u_dir);            // larger = farther from the viewer
    gl_Position = u_view_proj * vec4(in_pos, 1.0);
}
"""
_DEPTH_FS = """
in float v_depth;
out float f_depth;
void main() { f_depth = v_depth; }
"""


def bake_occlusion(topology: RenderTopology, positions: np.ndarray, *, directions: int = 96,
                   resolution: int = 384, bias: float = 0.004) -> np.ndarray:
    """Ambient visibility per geometry vertex, for ``Renderer.render(occlusion=...)``.

    For each of ``directions`` directions over the sphere the whole mesh is drawn as a
    depth map; a vertex counts as lit from a direction when nothing lies in front of it
    there. Visibility is averaged with cosine weights over the hemisphere around the vertex
    normal: 1 = open sky, 0 = fully enclosed. About 0.5-0.8 s for the head on llvmpipe:
    bake once on the neutral pose (sockets and creases change little with expression), or
    per frame where that matters.

    Parameters
    ----------
    topology : RenderTopology
    positions : (N_geo, 3) float
    directions : int
        Number of sample directions (more = smoother).
    resolution : int
        Depth-map size in pixels over the mesh's bounding sphere.
    bias : float
        Depth tolerance in world units (decimetres) against self-occlusion.

    Returns
    -------
    (N_geo,) float32 in [0, 1]; rows past ``topology.n_geo`` are 1.
    """
    p_all = np.asarray(positions, dtype=np.float32)
    n_geo = topology.n_geo
    if p_all.ndim != 2 or p_all.shape[1] != 3 or len(p_all) < n_geo:
        raise ValueError(f"positions must be (N_geo, 3) with N_geo >= {n_geo}, got {p_all.shape}")
    p = np.ascontiguousarray(p_all[:n_geo])
    faces = np.ascontiguousarray(topology.geo_faces.astype(np.uint32))
    normals = vertex_normals(p, faces.astype(np.int64))
    centre = 0.5 * (p.min(0) + p.max(0))
    radius = float(np.linalg.norm(p - centre, axis=1).max()) * 1.01 + 1e-6
    ctx = gl_context()
    objs = []
    try:
        prog = compile_program(ctx, "#version 330 core\n" + _DEPTH_VS, "#version 330 core\n" + _DEPTH_FS)
        objs.append(prog)
        vbo = ctx.buffer(p.tobytes()); objs.append(vbo)
        ibo = ctx.buffer(faces.tobytes()); objs.append(ibo)
        vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")], index_buffer=ibo,
                               index_element_size=4)
        objs.append(vao)
        color = ctx.renderbuffer((resolution, resolution), 1, dtype="f4"); objs.append(color)
        depth = ctx.depth_renderbuffer((resolution, resolution)); objs.append(depth)
        fbo = ctx.framebuffer(color_attachments=[color], depth_attachment=depth); objs.append(fbo)
        fbo.use()
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        seen = np.zeros(n_geo)
        weight = np.zeros(n_geo)
        half = resolution / 2.0
        for d in sphere_directions(directions):
            helper = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
            right = np.cross(helper, d); right /= np.linalg.norm(right)
            up = np.cross(d, right)
            # Orthographic view along -d, covering the bounding sphere.
            rot = np.stack([right, up, d])
            view = np.eye(4); view[:3, :3] = rot; view[:3, 3] = -rot @ (centre + 2 * radius * d)
            proj = np.diag([1 / radius, 1 / radius, -1 / (2 * radius), 1.0])
            proj[2, 3] = -1.0  # camera-space z in [-4r, 0] -> NDC [1, -1]
            prog["u_view_proj"].write((proj @ view).T.astype(np.float32).tobytes())
            prog["u_dir"].value = tuple(float(x) for x in d)
            fbo.clear(1e9, 0.0, 0.0, 0.0, depth=1.0)
            vao.render(ctx.TRIANGLES)
            dmap = np.frombuffer(fbo.read(components=1, dtype="f4"), dtype=np.float32)
            dmap = dmap.reshape(resolution, resolution)
            rel = p - centre
            col = np.clip(((rel @ right) / radius + 1) * half - 0.5, 0, resolution - 1)
            row = np.clip(((rel @ up) / radius + 1) * half - 0.5, 0, resolution - 1)
            c0 = np.floor(col).astype(int); r0 = np.floor(row).astype(int)
            c1 = np.minimum(c0 + 1, resolution - 1); r1 = np.minimum(r0 + 1, resolution - 1)
            # The farthest of the 4 neighbouring texels: lenient at silhouettes and edges.
            front = np.maximum(np.maximum(dmap[r0, c0], dmap[r0, c1]),
                               np.maximum(dmap[r1, c0], dmap[r1, c1]))
            own = -(p @ d)
            w = np.clip(normals @ d, 0.0, None)
            seen += w * (own <= front + bias)
            weight += w
    finally:
        for obj in reversed(objs):
            obj.release()
    occ = np.ones(len(p_all), dtype=np.float32)
    occ[:n_geo] = np.where(weight > 0, seen / np.maximum(weight, 1e-12), 1.0)
    return occ
