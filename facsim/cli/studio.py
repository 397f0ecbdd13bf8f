"""The CLI's ``facsim studio``: the browser workbench (:mod:`facsim.studio`)."""
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


def add_commands(sub) -> None:
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
    _check_free(args.host, args.port)
    from facsim.studio.server import serve

    serve(host=args.host, port=args.port, open_browser=args.open, token=args.token, max_pending=args.queue)


def _check_free(host: str, port: int) -> None:
    """Fail in one line, before starting anything, when the address cannot be used."""
    import socket

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as exc:
        raise ValueError(f"--host {host!r} is not an address of this machine: {exc.strerror}") from None
    family, _, _, _, address = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            raise ValueError(f"cannot listen on {host}:{port}: {exc.strerror or exc} "
                             f"(another program uses it? try --port {port + 1})") from None

