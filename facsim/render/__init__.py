"""Rendering with moderngl on a headless EGL context: the only package that imports moderngl.

``renderer`` (the Renderer resource), ``inputs`` (appearance and topology data),
``geometry`` (normals and per-vertex attributes), ``camera`` (views and
framing), ``gl`` (context and shaders), ``occlusion`` (baked ambient
visibility), ``shaders/`` (GLSL).
"""
