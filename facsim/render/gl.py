"""The process's OpenGL context and the shader sources, shared by everything that draws.

One context per process (EGL, created lazily on first use, reused by every
:class:`~facsim.render.Renderer` and by :func:`~facsim.render_occlusion.bake_occlusion`,
and recreated in a forked child). Shaders are read from ``facsim/render/shaders`` with
their ``#include "name.glsl"`` lines expanded and a variant's ``#define`` lines put in front.
``moderngl`` is imported only when a context is first needed.
"""
from __future__ import annotations

import os
import re
import signal
import threading
from contextlib import contextmanager
from pathlib import Path


class RenderError(RuntimeError):
    """OpenGL could not be set up or used (no driver, context creation failed, ...)."""


_CTX = None
_CTX_PID = None
_CTX_LOCK = threading.Lock()


def gl_context():
    """The process's shared moderngl context (EGL, GL >= 3.3), created on first use."""
    global _CTX, _CTX_PID
    with _CTX_LOCK:
        if _CTX is None or _CTX_PID != os.getpid():
            _CTX = _create_context()
            _CTX_PID = os.getpid()
        return _CTX


def context_exists() -> bool:
    """Whether this process has created its OpenGL context (a process that has must not fork:
    the child's EGL would hang)."""
    return _CTX is not None and _CTX_PID == os.getpid()


def _create_context():
    import moderngl

    errors = []
    for kwargs in ({"backend": "egl"}, {}):  # EGL: headless Linux; {}: the platform default
        try:
            return moderngl.create_context(standalone=True, require=330, **kwargs)
        except Exception as exc:  # moderngl raises bare Exception subclasses per backend
            errors.append(f"{kwargs.get('backend', 'default')}: {exc}")
    raise RenderError("could not create an OpenGL 3.3 context (" + "; ".join(errors) + "). On "
                      "Debian/Ubuntu install libegl1 libgl1 libgl1-mesa-dri for headless Mesa.")


_SHADER_DIR = Path(__file__).with_name("shaders")

#: The signals the CLI turns into KeyboardInterrupt (facsim.cli._stop_on_signals).
_STOP_SIGNALS = {getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)}


@contextmanager
def _signals_held():
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then let them through.

    moderngl builds a program's uniform and attribute objects in C through Python calls; a
    KeyboardInterrupt raised by a signal handler inside them is not checked for, and the
    process dies of SIGSEGV instead of cleaning up (tests/test_video.py's SIGTERM test caught
    it while a video's shaders compiled)."""
    if not hasattr(signal, "pthread_sigmask"):  # not POSIX
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def compile_program(ctx, vertex_shader: str, fragment_shader: str):
    """``ctx.program(...)`` with stop signals held until it returns (:func:`_signals_held`)."""
    with _signals_held():
        return ctx.program(vertex_shader=vertex_shader, fragment_shader=fragment_shader)


def _shader_source(name: str, defines: dict[str, object]) -> str:
    text = (_SHADER_DIR / name).read_text()
    for included in re.findall(r'^#include "([\w.]+)"$', text, flags=re.M):
        text = text.replace(f'#include "{included}"', (_SHADER_DIR / included).read_text())
    head = ["#version 330 core"] + [f"#define {k} {v}".rstrip() for k, v in defines.items()]
    return "\n".join(head) + "\n#line 1\n" + text


def _set_uniform(program, name: str, value) -> None:
    """Set a uniform if the compiler kept it (moderngl raises KeyError for removed ones)."""
    try:
        uniform = program[name]
    except KeyError:
        return
    uniform.value = value
