"""The package's layout stays honest: imports run downward, GL stays in render/, engines never draw.

Reads every module's imports with ``ast`` (module level and inside functions: a
lazy import is still a dependency) and checks the rules the README's
"Architecture" section states.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "facsim"

#: Subpackages, lowest first: each may import only from those before it (and top-level helpers).
LAYERS = ("facs", "head", "engines", "media", "render", "speech", "timeline", "exchange", "analysis", "validate",
          "batch", "studio", "cli")
#: Top-level modules and what they may import.
TOP_LEVEL = {"_data": set(), "atomic": set(), "__main__": {"cli"},
             "face": {"facs", "head", "engines", "render", "media"},
             "pipeline": {"face", "media", "timeline", "speech", "atomic"}}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Absolute names of the facsim modules (and third-party roots) ``path`` imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            out.add(module)
            out.update(f"{module}.{alias.name}" for alias in node.names)  # "from facsim.x import y" may be a module
    return out


MODULES = {_module_name(p): _imports(p) for p in sorted(PACKAGE.rglob("*.py"))}


def _unit(module: str) -> str | None:
    """The layer or top-level module a facsim module belongs to (None outside facsim)."""
    parts = module.split(".")
    if parts[0] != "facsim" or len(parts) < 2:
        return None
    return parts[1]


def _internal(imports: set[str]) -> set[str]:
    return {m for m in imports if m in MODULES}


def test_no_import_loops_between_modules():
    graph = {m: _internal(i) - {m} for m, i in MODULES.items()}
    # a package's __init__ importing its own submodules is how Python packages work: not a loop
    graph = {m: {d for d in deps if not d.startswith(m + ".")} for m, deps in graph.items()}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for dep in graph[node]:
            if state.get(dep) == 1:
                cycle = stack[stack.index(dep):] + [dep]
                pytest.fail("import loop: " + " -> ".join(cycle))
            if dep not in state:
                visit(dep)
        stack.pop()
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module)


def test_only_render_imports_moderngl():
    offenders = [m for m, imports in MODULES.items()
                 if any(i == "moderngl" or i.startswith("moderngl.") for i in imports)
                 and not m.startswith("facsim.render")]
    assert offenders == []


def test_engines_never_import_the_renderer():
    offenders = {m: sorted(i for i in _internal(imports) if i.startswith("facsim.render"))
                 for m, imports in MODULES.items() if m.startswith("facsim.engines")}
    assert {m: i for m, i in offenders.items() if i} == {}


def test_subpackages_import_only_lower_layers():
    rank = {layer: k for k, layer in enumerate(LAYERS)}
    wrong = []
    for module, imports in MODULES.items():
        own = _unit(module)
        for dep in _internal(imports):
            other = _unit(dep)
            if other is None or other == own:
                continue
            if own in rank and other in rank and rank[other] > rank[own]:
                wrong.append(f"{module} imports {dep} ({own} is below {other})")
            elif own in rank and other in TOP_LEVEL and other not in ("_data", "atomic"):
                if not (own in ("cli", "studio", "batch", "validate", "analysis", "speech")):
                    wrong.append(f"{module} imports {dep} (top-level {other} wires the layers together)")
            elif own in TOP_LEVEL and other not in TOP_LEVEL[own] | {"_data", "atomic", "facsim"} \
                    and other not in ("facs", "head", "engines", "render", "media", "timeline"):
                wrong.append(f"{module} imports {dep}")
    assert wrong == []


def test_the_facs_layer_is_pure_python():
    heavy = ("numpy", "scipy", "moderngl", "PIL", "imageio")
    offenders = {m: sorted(i for i in imports if i.split(".")[0] in heavy)
                 for m, imports in MODULES.items() if m.startswith("facsim.facs")}
    assert {m: i for m, i in offenders.items() if i} == {}


def test_help_imports_no_gl_scipy_or_yaml():
    code = ("import sys, contextlib, io\n"
            "from facsim.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    try: main(['--help'])\n"
            "    except SystemExit: pass\n"
            "print(sorted(m for m in ('moderngl', 'scipy', 'yaml', 'numpy', 'fastapi', 'dask') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_version_flag():
    from facsim import __version__

    out = subprocess.run([sys.executable, "-m", "facsim", "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == f"facsim {__version__}"
