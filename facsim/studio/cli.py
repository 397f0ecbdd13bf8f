"""``facsim studio``: the browser workbench (registered by facsim's CLI as a command group)."""
from __future__ import annotations

import argparse


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 < port < 65536:
        raise argparse.ArgumentTypeError(f"port must be a number from 1 to 65535, got {text!r}")
    return port


def add_commands(sub, *_) -> None:
    p = sub.add_parser("studio", help="open the browser workbench: sliders, 3-D preview, timeline, exports")
    p.add_argument("--port", type=_port, default=8000, help="port to listen on (default 8000)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1, this machine only; any other needs the "
                        "printed token)")
    p.add_argument("--open", action="store_true", help="open the page in a web browser")
    p.add_argument("--token", help="token to require (default: a random one when --host is not loopback)")
    p.add_argument("--queue", type=int, default=8, help="most renders waiting at once; more are refused (503)")
    p.set_defaults(handler=cmd_studio)


def cmd_studio(args) -> None:
    from importlib.util import find_spec

    if find_spec("fastapi") is None or find_spec("uvicorn") is None:
        raise ValueError("the studio needs its extra: pip install 'facsim[studio]' (or run install.sh)")
    if args.queue < 1:
        raise ValueError(f"--queue must be at least 1, got {args.queue}")
    from .server import serve

    try:
        serve(host=args.host, port=args.port, open_browser=args.open, token=args.token, max_pending=args.queue)
    except OSError as exc:
        raise ValueError(f"cannot listen on {args.host}:{args.port}: {exc.strerror or exc}") from None


def main(argv=None) -> int:
    """``python -m facsim.studio``: the same command without the rest of the CLI."""
    parser = argparse.ArgumentParser(prog="facsim studio")
    sub = parser.add_subparsers(dest="command")
    add_commands(sub)
    args = parser.parse_args(["studio", *(argv or [])])
    try:
        args.handler(args)
    except KeyboardInterrupt:
        return 130
    except ValueError as exc:
        print(f"facsim: error: {exc}")
        return 2
    return 0
