"""facsim studio: a browser workbench over facsim for people without 3-D skills.

``facsim studio`` starts a local web server (:mod:`facsim.studio.server`) with
one page: AU sliders and a FACS string kept in sync, emotion presets,
characters, a timeline editor and exports. The page previews the face live in
three.js from facsim's own ``.glb`` (every AU is a morph target), and asks the
server for exact renders, which one worker process makes
(:mod:`facsim.studio.worker`, the only process with an OpenGL context).

Needs the ``studio`` extra (FastAPI, uvicorn); three.js is fetched from the
npm registry into facsim's cache on first use (:mod:`facsim.studio.vendor`).
"""
