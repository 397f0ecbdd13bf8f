"""A load probe for a running studio: many render requests at once, then a health check.

Every request must be answered (200 with a PNG) or refused cleanly (503 with a
JSON error and ``Retry-After``); anything else — a hang, a reset connection, a
500 — counts as ``broken``. While the requests run, the resident memory of the
server and its worker is sampled.

    python -m facsim.studio.loadtest http://127.0.0.1:8000 [-n 50] [--size 96] [--pid SERVER_PID]
"""
from __future__ import annotations

import argparse
import json
import statistics
import threading
import time
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path


def process_tree_rss(pid: int) -> int:
    """Resident bytes of ``pid`` and all its descendants (Linux /proc)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
        except (OSError, IndexError, ValueError):
            continue
    total, todo = 0, [pid]
    while todo:
        p = todo.pop()
        try:
            for line in Path(f"/proc/{p}/status").read_text().splitlines():
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1]) * 1024
        except OSError:
            pass
        todo.extend(children.get(p, []))
    return total


def _post(url: str, body: dict, headers: dict, timeout: float) -> tuple[int, float, bytes, dict]:
    data = json.dumps(body).encode()
    request = urllib.request.Request(url, data=data, headers={"Content-Type": "application/json", **headers})
    start = time.perf_counter()
    try:
        with urllib.request.urlopen(request, timeout=timeout) as response:
            return response.status, time.perf_counter() - start, response.read(), dict(response.headers)
    except urllib.error.HTTPError as exc:
        return exc.code, time.perf_counter() - start, exc.read(), dict(exc.headers)
    except OSError as exc:           # refused, reset or timed out: not a clean answer
        return -1, time.perf_counter() - start, str(exc).encode(), {}


def clean(status: int, payload: bytes, headers: dict) -> str:
    """'served', 'refused' or 'broken' for one response."""
    if status == 200 and payload.startswith(b"\x89PNG"):
        return "served"
    if status in (429, 503):
        try:
            json.loads(payload)["error"]
        except (ValueError, KeyError, TypeError):
            return "broken"
        return "refused" if any(k.lower() == "retry-after" for k in headers) else "broken"
    return "broken"


def run(base_url: str, n: int = 50, *, size: int = 96, pid: int | None = None, token: str | None = None,
        timeout: float = 120.0) -> dict:
    """Fire ``n`` concurrent renders at ``base_url``; returns counts, latencies (s), peak memory and health."""
    base_url = base_url.rstrip("/")
    headers = {"X-Facsim-Token": token} if token else {}
    peak = [process_tree_rss(pid) if pid else 0]
    stop = threading.Event()

    def sample():
        while not stop.wait(0.05):
            peak[0] = max(peak[0], process_tree_rss(pid))

    sampler = threading.Thread(target=sample, daemon=True)
    if pid:
        sampler.start()
    barrier = threading.Barrier(n)

    def one(i: int):
        barrier.wait()     # all at once
        body = {"expression": f"6+12@{(i % 10 + 1) / 10}", "character": "ava", "options": {"size": size}}
        return _post(f"{base_url}/api/render", body, headers, timeout)

    start = time.perf_counter()
    with ThreadPoolExecutor(max_workers=n) as pool:
        results = list(pool.map(one, range(n)))
    wall = time.perf_counter() - start
    stop.set()
    if pid:
        sampler.join()
    kinds = [clean(status, payload, hdrs) for status, _, payload, hdrs in results]
    served = [t for (_, t, _, _), k in zip(results, kinds) if k == "served"]
    refused = [t for (_, t, _, _), k in zip(results, kinds) if k == "refused"]
    # The server counts a render done once its response is sent, which may be just after the client
    # has it (seen under load: pending 1): health is read until nothing is pending, for up to 10 s.
    settle = time.perf_counter() + 10.0
    while True:
        try:
            with urllib.request.urlopen(urllib.request.Request(f"{base_url}/api/health", headers=headers),
                                        timeout=30) as response:
                health = json.loads(response.read())
        except OSError as exc:
            health = {"ok": False, "error": str(exc)}
        if not health.get("ok") or not health.get("pending") or time.perf_counter() > settle:
            break
        time.sleep(0.1)

    def stats(times):
        return {"median": statistics.median(times), "max": max(times)} if times else None

    return {"requests": n, "served": len(served), "refused": len(refused), "broken": kinds.count("broken"),
            "served_latency": stats(served), "refused_latency": stats(refused), "wall": wall,
            "peak_rss": peak[0], "health_after": health,
            "broken_examples": [r[2][:200].decode("utf-8", "replace") for r, k in zip(results, kinds)
                                if k == "broken"][:3]}


def describe(result: dict) -> str:
    lines = [f"{result['requests']} concurrent renders: {result['served']} served, {result['refused']} refused "
             f"(503), {result['broken']} broken, in {result['wall']:.2f} s"]
    for kind in ("served", "refused"):
        s = result[f"{kind}_latency"]
        if s:
            lines.append(f"  {kind}: median {s['median'] * 1000:.0f} ms, max {s['max'] * 1000:.0f} ms")
    if result["peak_rss"]:
        lines.append(f"  peak memory, server + worker: {result['peak_rss'] / 2**20:.0f} MiB")
    health = result["health_after"]
    lines.append(f"  health after: ok={health.get('ok')} pending={health.get('pending')} "
                 f"served={health.get('served')} refused={health.get('refused')}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m facsim.studio.loadtest", description=__doc__.split("\n")[0])
    parser.add_argument("url", help="the studio's address, e.g. http://127.0.0.1:8000")
    parser.add_argument("-n", type=int, default=50, help="concurrent requests (default 50)")
    parser.add_argument("--size", type=int, default=96, help="image size (default 96)")
    parser.add_argument("--pid", type=int, help="server process id, to sample its memory (and its worker's)")
    parser.add_argument("--token", help="the studio's token, if it has one")
    args = parser.parse_args(argv)
    result = run(args.url, args.n, size=args.size, pid=args.pid, token=args.token)
    print(describe(result))
    return 0 if result["broken"] == 0 and result["health_after"].get("ok") else 1


if __name__ == "__main__":
    raise SystemExit(main())
