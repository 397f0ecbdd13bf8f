"""The studio's front door: token, ``Host`` check and body size limit, before any handler runs.

Loopback by default, and then only loopback ``Host`` headers are accepted, so a
web page elsewhere cannot reach the studio through DNS rebinding; on any other
address a token is required (``?token=`` once, which sets a cookie, or the
``X-Facsim-Token`` header). Bodies larger than the limit get 413 without
being read further.
"""
from __future__ import annotations

import hmac

from fastapi.responses import JSONResponse

TOKEN_COOKIE = "facsim_token"
LOOPBACK = {"127.0.0.1", "localhost", "::1", "[::1]"}


def error(status: int, message: str, **extra) -> JSONResponse:
    return JSONResponse({"error": message, **extra}, status_code=status)


class Guard:
    """ASGI middleware: token check, ``Host`` check and the body size limit, before any handler runs."""

    def __init__(self, app, *, token: str | None, allowed_hosts: set[str] | None, max_body: int,
                 uploads: dict[str, int] | None = None):
        self.app, self.token, self.allowed_hosts, self.max_body = app, token, allowed_hosts, max_body
        #: path → its own, larger body limit (file uploads)
        self.uploads = uploads or {}

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        problem = self._refuse(scope, headers)
        if problem is not None:
            return await problem(scope, receive, send)
        limit = self.uploads.get(scope.get("path", ""), self.max_body)
        length = headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > limit):
            return await error(413, f"request body is larger than {limit} bytes")(scope, receive, send)
        seen = 0

        async def limited_receive():
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > limit:
                raise _TooLarge()
            return message

        try:
            await self.app(scope, limited_receive, send)
        except _TooLarge:
            await error(413, f"request body is larger than {limit} bytes")(scope, receive, send)

    def _refuse(self, scope, headers):
        if self.allowed_hosts is not None:
            host = headers.get("host", "").rsplit(":", 1)[0] if not headers.get("host", "").startswith("[") \
                else headers["host"].split("]")[0] + "]"
            if host not in self.allowed_hosts:
                return error(403, f"host {host!r} is not allowed; open the studio at http://127.0.0.1")
        if self.token is None:
            return None
        given = headers.get("x-facsim-token") or cookie(headers.get("cookie", ""), TOKEN_COOKIE) \
            or query(scope.get("query_string", b"").decode("latin-1"), "token")
        if given and hmac.compare_digest(given.encode(), self.token.encode()):
            return None
        return error(401, "this studio needs its token: open the address printed when `facsim studio` started "
                          "(…/?token=…)")


class _TooLarge(Exception):
    pass


def cookie(header: str, name: str) -> str | None:
    """The value of cookie ``name`` in a ``Cookie`` header, or None."""
    for part in header.split(";"):
        key, _, value = part.strip().partition("=")
        if key == name:
            return value
    return None


def query(text: str, name: str) -> str | None:
    """The first value of ``name`` in a URL query string, or None."""
    from urllib.parse import parse_qs

    values = parse_qs(text).get(name)
    return values[0] if values else None


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address) is this machine only."""
    import ipaddress

    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
