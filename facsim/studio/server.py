"""The studio's web server: one page, a JSON API, and the render queue behind it.

Handlers validate input (:mod:`facsim.studio.requests`), answer small
questions themselves (parse, catalogue, timeline curves) and send anything
that renders to the worker process through :class:`~facsim.studio.jobs.RenderQueue`.

Safety, by default: loopback only, a token elsewhere, size-limited bodies
(:mod:`facsim.studio.guard`); a bounded queue (a full queue answers 503 at
once); every error is JSON naming the problem; files are served only by job
id from the job's own folder.
"""
from __future__ import annotations

import asyncio
import hashlib
import json
import time
from collections import OrderedDict
from importlib import resources
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.responses import FileResponse, JSONResponse, Response, StreamingResponse

from . import compat, requests as checks, worker
from .guard import LOOPBACK, TOKEN_COOKIE, Guard, error, is_loopback, query
from .jobs import Busy, RenderQueue
from .requests import RequestError
from .vendor import VENDOR_ROOTS, VendorError, ensure_three, safe_vendor_path

#: Largest request body accepted (a timeline or character file is a few kB).
MAX_BODY = 1 << 20
#: Content types a page elsewhere can send without a CORS preflight (so never accepted as uploads).
SIMPLE_TYPES = ("application/x-www-form-urlencoded", "multipart/form-data", "text/plain")
STATIC_FILES = {"app.js": "text/javascript", "timeline.js": "text/javascript", "style.css": "text/css",
                "index.html": "text/html"}
THUMBNAIL_VERSION = 1
MEDIA_TYPES = {".png": "image/png", ".mp4": "video/mp4", ".webm": "video/webm", ".gif": "image/gif",
               ".glb": "model/gltf-binary", ".csv": "text/csv", ".facs": "text/plain", ".json": "application/json"}


async def json_body(request: Request):
    """The request's JSON. Only ``application/json`` is read: other pages cannot send that
    cross-origin without a CORS preflight, which this server never grants (no CSRF)."""
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind != "application/json":
        raise RequestError(f"send JSON with Content-Type: application/json, not {kind or 'no type'!r}", status=415)
    try:
        return json.loads(await request.body() or b"null")
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RequestError(f"request body is not valid JSON: {exc}", status=400) from None


async def json_object(request: Request, example: str) -> dict:
    """The request's JSON object (see :func:`json_body`); anything else is a 400 showing ``example``."""
    body = await json_body(request)
    if not isinstance(body, dict):
        raise RequestError(example, status=400)
    return body


def create_app(*, workdir, token: str | None = None, allowed_hosts: set[str] | None = None,
               max_pending: int = 8, max_body: int = MAX_BODY, max_upload: int = checks.MAX_UPLOAD,
               render_timeout: float = 300.0) -> FastAPI:
    """The studio application (the render worker starts with the app and stops with it).

    Parameters
    ----------
    workdir : path
        Job folders live under it; nothing is written elsewhere (besides facsim's cache).
    token : str, optional
        Required on every request when given.
    allowed_hosts : set of str, optional
        Accepted ``Host`` header names (without port); None accepts any.
    max_pending : int
        Render-queue bound; excess requests get 503.
    max_upload : int
        Largest file ``/api/analyse`` accepts, bytes (other bodies: ``max_body``).
    """
    from contextlib import asynccontextmanager

    state: dict = {}

    @asynccontextmanager
    async def lifespan(app):
        state["queue"] = RenderQueue(workdir, max_pending=max_pending)
        try:
            yield
        finally:
            await asyncio.get_running_loop().run_in_executor(None, state["queue"].close)

    app = FastAPI(title="facsim studio", lifespan=lifespan, docs_url=None, redoc_url=None, openapi_url=None)
    glb_cache: OrderedDict[str, bytes] = OrderedDict()

    def queue() -> RenderQueue:
        return state["queue"]

    async def work(fn, *args, timeout: float = render_timeout):
        """``fn(*args)`` in the worker; facsim's user errors become 422, anything else 500 (never a hang)."""
        try:
            return await queue().run(fn, *args, timeout=timeout)
        except (Busy, asyncio.TimeoutError, RequestError):
            raise
        except ValueError as exc:
            raise RequestError(" ".join(str(exc).split()), status=422) from None
        except Exception as exc:
            raise RequestError(f"the renderer failed: {type(exc).__name__}: {exc}", status=500) from None

    # ----------------------------------------------------------- errors ---
    @app.exception_handler(RequestError)
    async def _request_error(request, exc: RequestError):
        return JSONResponse(exc.to_json(), status_code=exc.status)

    @app.exception_handler(Busy)
    async def _busy(request, exc: Busy):
        return JSONResponse({"error": str(exc)}, status_code=503, headers={"Retry-After": "2"})

    @app.exception_handler(asyncio.TimeoutError)
    async def _timeout(request, exc):
        return error(504, "the renderer took too long; try a smaller size")

    @app.exception_handler(Exception)
    async def _internal(request, exc: Exception):
        if isinstance(exc, ValueError):   # facsim's own user errors raised in the worker
            return error(422, " ".join(str(exc).split()))
        return error(500, f"internal error: {type(exc).__name__}: {' '.join(str(exc).split())}")

    @app.exception_handler(404)
    async def _not_found(request, exc):
        return error(404, f"no such page or endpoint: {request.url.path}")

    @app.exception_handler(405)
    async def _method(request, exc):
        return error(405, f"{request.method} is not allowed on {request.url.path}")

    # ------------------------------------------------------------- page ---
    static = resources.files("facsim.studio") / "static"

    @app.get("/")
    async def page(request: Request):
        html = (static / "index.html").read_text(encoding="utf-8")
        response = Response(html, media_type="text/html", headers={"Cache-Control": "no-store"})
        if token and query(request.url.query, "token") == token:
            response.set_cookie(TOKEN_COOKIE, token, httponly=True, samesite="strict")
        return response

    @app.get("/static/{name}")
    async def static_file(name: str):
        if name not in STATIC_FILES:
            return error(404, f"no static file {name!r}")
        return Response((static / name).read_bytes(), media_type=STATIC_FILES[name],
                        headers={"Cache-Control": "no-cache"})

    @app.get("/vendor/three/{root}/{path:path}")
    async def vendor(root: str, path: str):
        if root not in VENDOR_ROOTS:
            return error(404, f"no vendor folder {root!r}")
        try:
            base = await asyncio.get_running_loop().run_in_executor(None, ensure_three)
        except VendorError as exc:
            return error(503, str(exc))
        file = safe_vendor_path(base / VENDOR_ROOTS[root], path)
        if file is None:
            return error(404, f"no three.js module {path!r}")
        return FileResponse(file, media_type="text/javascript", headers={"Cache-Control": "max-age=86400"})

    # ------------------------------------------------------ information ---
    @app.get("/api/health")
    async def health():
        q = queue()
        return {"ok": True, "pending": q.pending, "max_pending": q.max_pending, "served": q.served,
                "refused": q.refused, "jobs": len(q.jobs)}

    @app.get("/api/catalogue")
    async def catalogue():
        """The AU catalogue (regions, names, sides), intensity tables, views and the rigid head/eye motions."""
        morphs = compat.simulated_codes()
        units = [{"code": u.code, "name": u.name, "region": u.region, "unilateral": u.unilateral,
                  "description": u.description, "muscles": list(u.muscles), "simulated": u.code in morphs}
                 for u in compat.catalogue().values() if u.rendered]
        table = compat.rigid_table()
        rigid = {"head": {str(c): {k: v for k, v in s.items() if k in ("axis", "degrees", "translate")}
                          for c, s in table["head_motions"].items()},
                 "eyes": {str(c): {k: v for k, v in s.items() if k in ("axis", "left", "right")}
                          for c, s in table["eye_rotations"].items()}}
        return {"units": units, "regions": ["upper face", "lower face", "head", "eyes"],
                "intensity_tables": {k: dict(v) for k, v in compat.INTENSITY_TABLES.items()},
                "views": {k: {"yaw": v[0], "pitch": v[1]} for k, v in compat.VIEWS.items()},
                "engines": list(compat.ENGINES), "antialias": list(checks.ANTIALIAS), "rigid": rigid,
                "bodies": list(compat.body_styles()), "default_body": compat.DEFAULT_BODY,
                "max_size": checks.MAX_SIZE, "easings": list(compat.EASINGS),
                "voices": [v for v in compat.voice_names() if ":" not in v]}

    @app.get("/api/emotions")
    async def emotions():
        tables = compat.preset_tables()
        return {"names": list(compat.emotion_names()),
                "tables": {name: {"title": t.title, "source": t.source, "presets": dict(t.presets)}
                           for name, t in tables.items()}}

    @app.post("/api/parse")
    async def parse(request: Request):
        body = await json_object(request, "send {\"expression\": \"1+2+5B+26\"}")
        table = checks.intensities_table(body.get("intensities"))
        text = checks.expression_text(body.get("expression"), table)
        return {"expression": text, "units": checks.expression_units(text, table)}

    @app.post("/api/expression")
    async def expression(request: Request):
        body = await json_object(request, "send {\"levels\": {\"12\": {\"left\": 0.55, \"right\": 0.55}}}")
        table = checks.intensities_table(body.get("intensities"))
        return {"expression": checks.expression_from_levels(body.get("levels", {}), table)}

    @app.post("/api/emotion")
    async def emotion(request: Request):
        body = await json_object(request, "send {\"name\": \"surprise\"}")
        table = checks.intensities_table(body.get("intensities"))
        preset_table = body.get("table", compat.DEFAULT_TABLE)
        try:
            expr = compat.emotion(str(body.get("name", "")), table=preset_table, intensity=body.get("intensity", 1.0),
                                  intensities=table)
            if body.get("blend_with"):
                other = compat.emotion(str(body["blend_with"]), table=preset_table, intensities=table)
                expr = compat.blend(expr, other, body.get("weight", 0.5), table=preset_table, intensities=table)
        except (ValueError, TypeError) as exc:
            raise RequestError(str(exc), field="emotion") from None
        text = str(expr)
        return {"expression": text, "units": checks.expression_units(text, table)}

    # ------------------------------------------------------- characters ---
    @app.get("/api/characters")
    async def characters():
        presets = {name: checks.character_params(name) for name in compat.preset_names()}
        return {"presets": presets, "sliders": checks.face_sliders(), "ethnicities": list(compat.ETHNICITIES)}

    @app.get("/api/characters/{name}/thumbnail.png")
    async def thumbnail(name: str):
        if name not in compat.preset_names():
            return error(404, f"unknown character {name!r}; choose from {', '.join(compat.preset_names())}")
        params = checks.character_params(name)
        key = hashlib.sha256(json.dumps([THUMBNAIL_VERSION, params], sort_keys=True).encode()).hexdigest()[:12]
        path = compat.cache_dir() / "studio" / "thumbnails" / f"{name}-{key}.png"
        if not path.exists():
            await work(worker.thumbnail, name, str(path))
        return FileResponse(path, media_type="image/png", headers={"Cache-Control": "max-age=3600"})

    @app.post("/api/character")
    async def character(request: Request):
        """Check a character (preset name, random:SEED or parameters); returns its parameters."""
        body = await json_body(request)
        spec = body.get("character") if isinstance(body, dict) else None
        if isinstance(body, dict) and "random" in body:
            seed = body["random"]
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise RequestError(f"random needs a seed >= 0, got {seed!r}", field="random")
            spec = f"random:{seed}"
        return {"character": checks.character_params(spec)}

    @app.post("/api/character/yaml")
    async def character_yaml(request: Request):
        body = await json_body(request)
        params = checks.character_params(body.get("character") if isinstance(body, dict) else None)
        return Response(checks.character_yaml(params), media_type="application/yaml",
                        headers={"Content-Disposition": 'attachment; filename="character.yaml"'})

    @app.post("/api/character/load")
    async def character_load(request: Request):
        body = await json_body(request)
        return {"character": checks.character_from_yaml(body.get("text") if isinstance(body, dict) else None)}

    @app.post("/api/character/glb")
    async def character_glb(request: Request):
        """The character as facsim's ``.glb`` (AU morph targets) for the 3-D view."""
        body = await json_body(request)
        params = checks.character_params(body.get("character") if isinstance(body, dict) else None)
        key = json.dumps(params, sort_keys=True)
        if key not in glb_cache:
            glb_cache[key] = await work(worker.glb_bytes, params)
            while len(glb_cache) > 4:
                glb_cache.popitem(last=False)
        glb_cache.move_to_end(key)
        return Response(glb_cache[key], media_type="model/gltf-binary")

    # ---------------------------------------------------------- renders ---
    def render_spec(body) -> dict:
        if not isinstance(body, dict):
            raise RequestError("send {\"expression\": ..., \"character\": ..., \"options\": {...}}", status=400)
        table = checks.intensities_table(body.get("intensities"))
        return {"character": checks.character_params(body.get("character")),
                "engine": checks.engine(body.get("engine")),
                "expression": checks.expression_text(body.get("expression", "neutral"), table),
                "intensities": table,
                "options": checks.render_options(body.get("options"))}

    @app.post("/api/render")
    async def render(request: Request):
        """The exact image ``facsim render`` writes for the same expression, character and options."""
        spec = render_spec(await json_body(request))
        png = await work(worker.render_png, spec["character"], spec["engine"], spec["expression"],
                                spec["intensities"], spec["options"], timeout=render_timeout)
        return Response(png, media_type="image/png", headers={"X-Facsim-Expression": spec["expression"]})

    # --------------------------------------------------------- timeline ---
    @app.post("/api/timeline/preview")
    async def timeline_preview(request: Request):
        body = await json_body(request)
        # off the event loop: a speech clip is synthesised here (flite, a fraction of a second per sentence)
        return await asyncio.get_running_loop().run_in_executor(
            None, checks.timeline_preview, body.get("timeline") if isinstance(body, dict) else None)

    @app.post("/api/timeline/audio")
    async def timeline_audio(request: Request):
        """The timeline's speech as WAV (as long as the video), for playing along with the preview;
        204 when the timeline has no speech."""
        body = await json_body(request)
        wav = await asyncio.get_running_loop().run_in_executor(
            None, checks.timeline_wav, body.get("timeline") if isinstance(body, dict) else None)
        return Response(status_code=204) if wav is None else Response(wav, media_type="audio/wav")

    @app.post("/api/timeline/load")
    async def timeline_load(request: Request):
        body = await json_object(request, "send {\"name\": \"clip.yaml\", \"text\": ...}")
        return {"timeline": checks.timeline_from_text(body.get("name"), body.get("text"))}

    @app.post("/api/timeline/save")
    async def timeline_save(request: Request):
        body = await json_object(request, "send {\"timeline\": {...}, \"format\": \"yaml\"}")
        fmt = body.get("format", "yaml")
        text = checks.timeline_text(body.get("timeline"), fmt)
        return Response(text, media_type="application/yaml" if fmt == "yaml" else "application/json",
                        headers={"Content-Disposition": f'attachment; filename="timeline.{fmt}"'})

    @app.post("/api/timeline/stimulus")
    async def timeline_stimulus(request: Request):
        """A HapFACS stimulus (1 s onset, 1 s apex, 1 s offset by default) as a timeline document."""
        body = await json_object(request, "send {\"expression\": \"1+2+5B+26\"} or {\"emotion\": \"surprise\"}")
        table = checks.intensities_table(body.get("intensities"))
        name = body.get("emotion") or checks.expression_text(body.get("expression", "neutral"), table)
        timing = [checks.number(body.get(k, 1.0), k, 0.0, 60.0) for k in ("onset", "apex", "offset")]
        try:
            timeline = compat.stimulus_timeline(name, *timing, body.get("fps", 30.0),
                                                intensity=body.get("intensity", 1.0),
                                                easing=body.get("easing", "linear"), intensities=table)
        except (ValueError, TypeError) as exc:
            raise RequestError(str(exc), field="stimulus") from None
        return {"timeline": compat.timeline_to_dict(timeline)}

    # ------------------------------------------------------------- jobs ---
    @app.post("/api/jobs", status_code=202)
    async def start_job(request: Request):
        """Start an export: png, video (mp4/webm/gif), glb, arkit-csv or facs. Returns the job."""
        body = await json_object(request, "send {\"kind\": \"video\", \"timeline\": {...}, ...}")
        kind = checks.choice(body.get("kind"), ("png", "video", "glb", "arkit-csv", "facs"), "kind")
        if kind == "png":
            spec = render_spec(body)
        else:
            checks.timeline_from_document(body.get("timeline"))   # errors now, not in the worker
            spec = {"timeline": body["timeline"], "character": checks.character_params(body.get("character"))}
            if kind == "glb":
                spec["body"] = checks.body_style((body.get("options") or {}).get("body", compat.DEFAULT_BODY))
            if kind == "video":
                spec.update(format=checks.choice(body.get("format", "mp4"), checks.VIDEO_FORMATS, "format"),
                            engine=checks.engine(body.get("engine")),
                            options=checks.render_options(body.get("options"), video=True))
        job = queue().start_job(kind, spec)
        return job.to_json()

    def find_job(job_id: str):
        job = queue().job(job_id)
        if job is None:
            raise RequestError(f"no job {job_id!r}", field="id", status=404)
        return job

    @app.post("/api/analyse", status_code=202)
    async def analyse_upload(request: Request):
        """The camera processor on an uploaded image or short video (the raw file as the body).

        Starts an ``analyse`` job; its ``analysis.json`` holds the FACS string (image) or the
        analysed timeline (video). The file is stored only in the job's folder, under a name
        the server picks from its content.
        """
        kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
        if kind in SIMPLE_TYPES or not kind:
            # types a form on another page could send without a CORS preflight: never read them
            raise RequestError("send the file itself as the body with its type (e.g. Content-Type: image/png)",
                               field="file", status=415)
        data = await request.body()
        media, suffix = checks.upload_kind(data)
        job = queue().start_job("analyse", {"kind": media, "upload": "upload" + suffix},
                                files={"upload" + suffix: data})
        return job.to_json()

    @app.get("/api/jobs/{job_id}")
    async def job_status(job_id: str):
        return find_job(job_id).to_json()

    @app.post("/api/jobs/{job_id}/cancel")
    async def job_cancel(job_id: str):
        job = find_job(job_id)
        queue().cancel(job)
        return job.to_json()

    @app.get("/api/jobs/{job_id}/events")
    async def job_events(job_id: str, request: Request):
        """Server-sent events: ``progress`` while the job runs, then one ``done``, ``failed`` or ``cancelled``."""
        job = find_job(job_id)

        async def events():
            sent, idle, finished_at = 0, 0, None
            yield f"event: progress\ndata: {json.dumps(job.to_json())}\n\n"
            while True:
                while sent < len(job.history):        # every step the worker reported, in order
                    done, total = job.history[sent]
                    sent += 1
                    snapshot = dict(job.to_json(), state="running", done=done, total=total)
                    yield f"event: progress\ndata: {json.dumps(snapshot)}\n\n"
                    idle = 0
                if job.finished:
                    # the last reports may still be on their way from the worker: wait for them briefly
                    finished_at = finished_at or time.monotonic()
                    caught_up = job.history and job.history[-1][0] >= job.history[-1][1]
                    if caught_up or job.state != "done" or time.monotonic() - finished_at > 1.0:
                        yield f"event: {job.state}\ndata: {json.dumps(job.to_json())}\n\n"
                        return
                idle += 1
                if idle % 40 == 0:
                    yield ": still working\n\n"
                if await request.is_disconnected():
                    return
                await asyncio.sleep(0.1)

        return StreamingResponse(events(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-store", "X-Accel-Buffering": "no"})

    @app.get("/api/jobs/{job_id}/download")
    async def job_download(job_id: str):
        job = find_job(job_id)
        path = queue().download_path(job)
        if path is None:
            raise RequestError(f"job {job_id} has no file ({job.state})", field="id", status=409)
        return FileResponse(path, media_type=MEDIA_TYPES.get(path.suffix, "application/octet-stream"),
                            filename=path.name)

    return Guard(app, token=token, allowed_hosts=allowed_hosts, max_body=max_body,
                 uploads={"/api/analyse": max_upload})


def serve(*, host: str = "127.0.0.1", port: int = 8000, open_browser: bool = False, token: str | None = None,
          workdir=None, max_pending: int = 8, log_level: str = "warning") -> None:
    """Run the studio until Ctrl-C (``facsim studio``)."""
    import secrets
    import shutil

    import uvicorn

    from .jobs import default_workdir

    ensure_three()    # fetch three.js now, with a clear error, not when the page asks
    loopback = is_loopback(host)
    if not loopback and token is None:
        token = secrets.token_urlsafe(24)
    own_workdir = workdir is None
    workdir = Path(workdir) if workdir else default_workdir()
    app = create_app(workdir=workdir, token=token, allowed_hosts=LOOPBACK if loopback else None,
                     max_pending=max_pending)
    shown = "127.0.0.1" if host in ("0.0.0.0", "::") else host
    url = f"http://{'[' + shown + ']' if ':' in shown else shown}:{port}/" + (f"?token={token}" if token else "")
    print(f"facsim studio: {url}", flush=True)
    if not loopback:
        print(f"facsim studio: listening on {host} — anyone who can reach it needs the token above", flush=True)
    if open_browser:
        import threading
        import webbrowser

        threading.Timer(1.0, webbrowser.open, args=(url,)).start()
    try:
        uvicorn.run(app, host=host, port=port, log_level=log_level, timeout_graceful_shutdown=5)
    finally:
        if own_workdir:
            shutil.rmtree(workdir, ignore_errors=True)


__all__ = ["create_app", "serve", "is_loopback"]
