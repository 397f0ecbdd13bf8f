"""Studio load: bursts of concurrent render requests against a local ``facsim studio``.

Starts a studio on 127.0.0.1 (a free port, its default queue bound of 8), warms
it with one render, then fires ``--requests`` renders at once, ``--repeats``
times. Prints what was served, refused (503) or broken, latencies, the peak
memory of server + worker, and the server's health after; the single-render
latency measured in the same run is the baseline. Stops the server itself.

    python benchmarks/bench_studio_load.py [--requests 50] [--repeats 3] [--size 96]
"""
from __future__ import annotations

import argparse
import json
import socket
import statistics
import subprocess
import sys
import time
import urllib.request


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def one_render(url: str, size: int) -> float:
    body = json.dumps({"expression": "6+12", "character": "ava", "options": {"size": size}}).encode()
    request = urllib.request.Request(f"{url}/api/render", data=body, headers={"Content-Type": "application/json"})
    start = time.perf_counter()
    with urllib.request.urlopen(request, timeout=300) as response:
        response.read()
    return time.perf_counter() - start


def main(argv=None) -> int:
    from facsim.studio.loadtest import describe, process_tree_rss, run

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--requests", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--size", type=int, default=96)
    args = parser.parse_args(argv)
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    server = subprocess.Popen([sys.executable, "-m", "facsim.studio", "--port", str(port)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(300):
            try:
                urllib.request.urlopen(f"{url}/api/health", timeout=2)
                break
            except OSError:
                time.sleep(0.2)
        cold = one_render(url, args.size)
        warm = statistics.median(one_render(url, args.size) for _ in range(5))
        idle_rss = process_tree_rss(server.pid)
        print(f"studio on {url}: first render {cold:.2f} s, warm render {warm * 1000:.0f} ms (median of 5), "
              f"idle memory {idle_rss / 2**20:.0f} MiB")
        results = []
        for i in range(args.repeats):
            result = run(url, args.requests, size=args.size, pid=server.pid)
            results.append(result)
            print(f"burst {i + 1}: " + describe(result))
        served = statistics.median(r["served_latency"]["median"] for r in results if r["served_latency"])
        refused = statistics.median(r["refused_latency"]["median"] for r in results if r["refused_latency"])
        peak = max(r["peak_rss"] for r in results)
        print(f"summary over {args.repeats} bursts of {args.requests}: "
              f"served {[r['served'] for r in results]}, refused {[r['refused'] for r in results]}, "
              f"broken {sum(r['broken'] for r in results)}; served median {served * 1000:.0f} ms "
              f"({served / warm:.1f}x one warm render), refusals answered in {refused * 1000:.0f} ms; "
              f"peak memory {peak / 2**20:.0f} MiB ({peak / idle_rss:.2f}x idle); "
              f"healthy after: {all(r['health_after'].get('ok') for r in results)}")
        return 0 if all(r["broken"] == 0 for r in results) else 1
    finally:
        server.terminate()
        server.wait(timeout=30)


if __name__ == "__main__":
    raise SystemExit(main())
