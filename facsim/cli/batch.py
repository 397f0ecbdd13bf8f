"""``facsim batch SPEC -o DIR``: render a stimulus set (see :mod:`facsim.batch`)."""
from __future__ import annotations

import argparse


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"--workers must be a whole number >= 1, got {text!r}")
    return value


def _scheduler(text: str) -> str:
    if not text.startswith(("tcp://", "tls://", "ucx://", "inproc://")) or "://" == text[-3:]:
        raise argparse.ArgumentTypeError(f"--scheduler must be an address like tcp://HOST:PORT, got {text!r}")
    return text


def add_commands(sub) -> None:
    """Register ``batch`` on the ``facsim`` subcommand parser."""
    import os

    p = sub.add_parser("batch", help="render a stimulus set from a spec (stills, videos, glb + manifest)",
                       description="Render every file a stimulus-set spec describes into DIR, with "
                                   "manifest.csv (a PsychoPy/jsPsych conditions file) and manifest.json. "
                                   "Rerun the same command after an interruption to finish the set.")
    p.add_argument("spec", help="stimulus-set spec (YAML or JSON; schema: facsim batch --schema)", nargs="?")
    p.add_argument("-o", "--output", help="output folder")
    p.add_argument("--workers", "-j", type=_workers, default=os.cpu_count() or 1,
                   help="worker processes (default: the number of cores)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--dask", action="store_true", help="run on a Dask LocalCluster of --workers processes")
    where.add_argument("--scheduler", type=_scheduler, metavar="tcp://HOST:PORT",
                       help="run on an existing Dask cluster")
    p.add_argument("--force", action="store_true", help="replace a set made from a different spec in the folder")
    p.add_argument("--dry-run", action="store_true", help="check the spec and list the files, render nothing")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.add_argument("--schema", action="store_true", help="print the spec's JSON Schema and exit")
    p.set_defaults(handler=cmd_batch)


def cmd_batch(args) -> None:
    from facsim.cli import CliError

    if args.schema:
        from facsim.batch.spec import _schema_text

        print(_schema_text(), end="")
        return
    if args.spec is None:
        raise CliError("batch needs a SPEC file (or --schema)")
    from facsim.batch.items import expand
    from facsim.batch.spec import load_spec

    spec = load_spec(args.spec)
    if args.dry_run:
        items = expand(spec)
        kinds = {k: sum(it.kind == k for it in items) for k in ("still", "video", "glb")}
        for item in items:
            print(f"{item.file}\t{item.key}" if item.file != item.key else item.file)
        print(f"{len(items)} files: " + ", ".join(f"{n} {k}{'s' if n != 1 else ''}" for k, n in kinds.items() if n))
        return
    if not args.output:
        raise CliError("batch needs -o DIR, the output folder")
    if (args.dask or args.scheduler):
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise CliError("--dask and --scheduler need Dask: pip install 'facsim[dask]'") from None
    from facsim.batch.run import BatchError, run_batch

    try:
        result = run_batch(spec, args.output, workers=args.workers, dask=args.dask, scheduler=args.scheduler,
                           force=args.force, progress=not args.quiet)
    except BatchError as exc:
        raise CliError(str(exc)) from None
    except KeyboardInterrupt:
        import sys

        print(f"facsim: batch interrupted; rerun the same command to finish the set in {args.output}",
              file=sys.stderr)
        raise
    made = f"{result.rendered} rendered" + (f", {result.resumed} already done" if result.resumed else "")
    print(f"wrote {result.items} files to {args.output} ({made}) in {result.seconds:.1f} s; "
          f"manifest: {result.manifest}")
    if spec.naming == "blind":
        from pathlib import Path

        print(f"blind names: what each file shows is in {Path(args.output) / spec.key_file} "
              "(keep it from the coders)")
