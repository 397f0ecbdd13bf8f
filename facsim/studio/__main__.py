"""``python -m facsim.studio [--port 8000] [--host 127.0.0.1] [--open]``."""
import sys

from .cli import main

sys.exit(main(sys.argv[1:]))
