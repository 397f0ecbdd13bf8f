"""``python -m facsim.studio [--port 8000] [--host 127.0.0.1] [--open]``: the same as ``facsim studio``."""
import sys

from facsim.__main__ import run

sys.exit(run(["studio", *sys.argv[1:]]))
