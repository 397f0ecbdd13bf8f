"""facsim studio: a browser workbench over facsim for people without 3-D skills.

``facsim studio`` starts a local web server (:mod:`facsim.studio.server`) with
one page: AU sliders and a FACS string kept in sync, emotion presets,
characters, a timeline editor and exports. The page previews the face live in
three.js from facsim's own ``.glb`` (every AU is a morph target), and asks the
server for exact renders, which one worker process makes
(:mod:`facsim.studio.worker`, the only process with an OpenGL context).

Needs the ``studio`` extra (FastAPI, uvicorn); three.js is fetched from the
npm registry into facsim's cache on first use (:mod:`facsim.studio.vendor`).

HTTP API (JSON in and out; errors are ``{"error": ..., "field": ...}`` with a 4xx/5xx status)::

    GET  /api/health                      queue state
    GET  /api/catalogue                   AUs by region (facsim/data/action_units.yaml), intensity
                                          tables, views, easings, head/eye motions
    GET  /api/emotions                    preset tables
    POST /api/parse        {expression}   canonical FACS + per-side levels; errors carry position, token
    POST /api/expression   {levels}       slider levels → canonical FACS
    POST /api/emotion      {name, table, intensity, blend_with, weight}
    GET  /api/characters                  presets and face-shape slider names
    GET  /api/characters/NAME/thumbnail.png
    POST /api/character    {character} | {random: SEED}   checked parameters
    POST /api/character/yaml, /api/character/load, /api/character/glb
    POST /api/render       {expression, character, engine, options}   PNG, as ``facsim render``
    POST /api/timeline/preview | load | save | stimulus   (speech clips: {say, voice, start})
    POST /api/timeline/audio {timeline}   the speech as WAV (204 without speech)
    POST /api/jobs         {kind: png|video|glb|arkit-csv|facs, ...}   → job; then
    GET  /api/jobs/ID, /api/jobs/ID/events (server-sent events), /api/jobs/ID/download
    POST /api/jobs/ID/cancel
    POST /api/analyse      (the raw image or video file)   → an ``analyse`` job; its download is
                                          analysis.json: the FACS string, and for a video the timeline
"""
