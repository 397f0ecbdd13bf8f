"""A table of bad invocations: each exits 2 with exactly one line on stderr, no traceback, no files left.

Run in-process through :func:`facsim.cli.main` (fast: nothing here gets as far
as rendering). An unexpected internal error exits 1 with one "please report"
line; ``--debug`` shows its traceback instead.
"""
from __future__ import annotations

import os

import pytest

from facsim.cli import main

OPENFACE = "frame, face_id, timestamp, confidence, success, AU01_r, AU12_r\n"
FILES = {
    "ok.yaml": "tracks: [{au: 12, start: 0, end: 1}]\n",
    "alias.yaml": "a: &a [x, x, x]\nb: &b [*a, *a, *a]\ntracks: *b\n",
    "deep.yaml": "tracks: " + "[" * 500 + "]" * 500 + "\n",
    "long.yaml": "duration: 1.0e+9\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "late.yaml": "tracks: [{au: 12, start: 1.0e+17, end: 2.0e+17}]\n",
    "mixed.yaml": "tracks: []\nduration: 1\n1: a\nzz: b\n",
    "intx.yaml": "fps: !!int x\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "huge_error.yaml": "tracks: [{au: 12, start: 0, end: 1, side: " + "x" * 50_000 + "}]\n",
    "binary.yaml": b"tracks: [] # \xff\xfe\n",
    "arabic.yaml": "tracks: [{facs: '\u0661\u0662', start: 0, end: 1}]\n",
    "notes.txt": "tracks: []\n",
    "ok.csv": OPENFACE + "1, 0, 0.0, 0.9, 1, 1.0, 2.0\n2, 0, 0.0333, 0.9, 1, 1.0, 2.0\n",
    "close.csv": OPENFACE + "1, 0, 0, 0.9, 1, 1.0, 2.0\n2, 0, 1e-320, 0.9, 1, 1.0, 2.0\n",
    "backwards.csv": OPENFACE + "1, 0, 1, 0.9, 1, 1.0, 2.0\n2, 0, 0.5, 0.9, 1, 1.0, 2.0\n",
    "binary.csv": b"\xff\xfe" + OPENFACE.encode(),
    "bad.facs": "facsim-notation 1\nAU12 0-1e17\n",
    "deep.json": '{"tracks": ' + "[" * 100_000 + "]" * 100_000 + "}",
    # a 150x120 black PNG: over the pixel limit the fixture sets
    "wide.png": b'\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x96\x00\x00\x00x\x08\x02\x00\x00\x00\x9f-\x9cG\x00\x00\x00KIDATx\x9c\xed\xc1\x01\r\x00\x00\x00\xc2\xa0\xf7Om\x0f\x07\x14\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x0f\x06\xd3h\x00\x01\xc6\xa4\x1e[\x00\x00\x00\x00IEND\xaeB`\x82',
    # 3 characters x 20 AUs x 5 intensities x 2 views x 2 sizes = 1,200 stills: over the fixture's limit
    "big_set.yaml": "characters: [ava, liam, zola]\nviews: [front, profile-left]\nsizes: [64, 128]\nblocks:\n"
                    "  - {name: b, aus: [1, 2, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 20, 22, 23, 24],\n"
                    "     intensities: [0.2, 0.4, 0.6, 0.8, 1.0], outputs: {stills: [1]}}\n",
}
#: Limits lowered for the table (they only concern the camera processor and batch specs).
LOW_LIMITS = {"FACSIM_MAX_IMAGE_PIXELS": "10000", "FACSIM_MAX_ITEMS": "1000"}

BAD = [
    # render: notation, options, outputs
    "render 99 -o x.png",
    "render 1+2+\u0661\u0662 -o x.png",
    "render " + "1" * 4301 + " -o x.png",
    "render 12@-0.5 -o x.png",
    "render 12@1e-1 -o x.png",
    "render 12 -o x.jpg",
    "render 12 -o x",
    "render 12 -o x.png --yaw inf",
    "render 12 -o x.png --yaw 1e9",
    "render 12 -o x.png --pitch 90",
    "render 12 -o x.png --pitch nan",
    "render 12 -o x.png --size 0",
    "render 12 -o x.png --size 100000",
    "render 12 -o x.png --size abc",
    "render 12 -o x.png --antialias 0",
    "render 12 -o x.png --antialias \u0664",
    "render 12 -o x.png --background #zzzzzz",
    "render 12 -o x.png --view nowhere",
    "render 12 -o x.png --engine nope",
    "render --emotion glee -o x.png",
    "render --emotion happiness --intensity 150% -o x.png",
    "render --timeline alias.yaml --time 1 -o x.png",
    "render --timeline ok.yaml --time -1 -o x.png",
    "render --timeline ok.yaml --time 99 -o x.png",
    "render --timeline missing.yaml --time 0 -o x.png",
    "render --time 1 12 -o x.png",
    "render 12",
    # animate: hostile timeline files and rates
    "animate alias.yaml -o x.mp4",
    "animate deep.yaml -o x.mp4",
    "animate deep.json -o x.mp4",
    "animate long.yaml -o x.mp4",
    "animate late.yaml -o x.mp4",
    "animate mixed.yaml -o x.mp4",
    "animate intx.yaml -o x.mp4",
    "animate huge_error.yaml -o x.mp4",
    "animate binary.yaml -o x.mp4",
    "animate arabic.yaml -o x.mp4",
    "animate notes.txt -o x.mp4",
    "animate missing.yaml -o x.mp4",
    "animate ok.yaml -o x.mp4 --fps 0",
    "animate ok.yaml -o x.mp4 --fps 1e6",
    "animate ok.yaml -o x.mp4 --fps nan",
    "animate ok.yaml -o x.mp4 --yaw=-inf",
    "animate ok.yaml -o x.mp4 --pitch=-1e400",
    # emotion
    "emotion glee -o x.mp4",
    "emotion happiness -o x.mp4 --onset -1",
    "emotion happiness -o x.mp4 --apex inf",
    "emotion happiness -o x.mp4 --fps 0",
    "emotion happiness -o x.mp4 --easing wobble",
    "emotion happiness -o x.mp4 --intensity 2",
    "emotion happiness -o x.mp4 --save-timeline t.txt",
    # plot
    "plot ok.yaml -o plot.jpg",
    "plot alias.yaml -o plot.png",
    # export
    "export glb -o x.txt",
    "export glb -o x.glb --aus \u0661\u0662",
    "export glb -o x.glb --timeline alias.yaml",
    "export arkit-csv ok.yaml -o x.txt",
    "export arkit-csv ok.yaml -o x.csv --fps -3",
    "export notation ok.yaml -o x.txt",
    "export notation deep.yaml -o x.facs",
    "export mesh 12 -o x.stl",
    "export mesh 99 -o x.obj",
    # import
    "import openface close.csv -o t.yaml",
    "import openface backwards.csv -o t.yaml",
    "import openface binary.csv -o t.yaml",
    "import openface ok.csv -o t.txt",
    "import openface ok.csv -o t.yaml --fps 0",
    "import openface ok.csv -o t.yaml --min-confidence 2",
    "import arkit-csv ok.csv -o t.yaml",
    "import notation bad.facs -o t.yaml",
    # camera processor
    "analyse ok.csv --threads 0",
    "analyse ok.csv --face -1",
    "analyse ok.csv --face \u0664",
    "retarget ok.csv -o x.mp4 --size 0",
    "validate --size 1e9",
    "analyse wide.png",
    "retarget wide.png -o x.mp4",
    # batch
    "batch big_set.yaml -o out --dry-run",
    # the command line itself
    "frobnicate",
    "",
]


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    for name, content in FILES.items():
        path = tmp_path / name
        path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FACSIM_DEBUG", raising=False)
    for name, value in LOW_LIMITS.items():
        monkeypatch.setenv(name, value)
    return tmp_path


def run(argv, capsys) -> tuple[int, str]:
    try:
        code = main(argv)
    except SystemExit as exc:      # argparse's usage errors
        code = exc.code
    return code, capsys.readouterr().err


def snapshot(folder) -> set[str]:
    return {os.path.relpath(os.path.join(root, name), folder)
            for root, dirs, files in os.walk(folder) for name in (*dirs, *files)}


@pytest.mark.parametrize("command", BAD, ids=lambda c: c[:50] or "(no command)")
def test_bad_invocation_is_one_line_exit_2_and_leaves_nothing(workdir, capsys, command):
    before = snapshot(workdir)
    code, err = run(command.split(), capsys)
    lines = err.strip().splitlines()
    assert code == 2, (code, err[:500])
    assert len(lines) == 1, err[:500]
    assert "Traceback" not in err
    assert len(lines[0]) < 700
    assert snapshot(workdir) == before


def test_messages_name_the_problem(workdir, capsys):
    expected = {
        "render 12 -o x.png --yaw inf": "--yaw: expected a finite number of degrees",
        "emotion glee -o x.mp4": "unknown emotion 'glee'",
        "render 12 -o x.jpg": "must end in .png",
        "export glb -o x.txt": "must end in .glb",
        "animate ok.yaml -o x.mp4 --fps 0": "--fps",
        "animate alias.yaml -o x.mp4": "alias.yaml:2: malformed YAML: YAML aliases",
        "animate long.yaml -o x.mp4": "FACSIM_MAX_FRAMES",
        "animate binary.yaml -o x.mp4": "binary.yaml: not UTF-8",
        "import openface close.csv -o t.yaml": "close.csv: timestamps",
        "analyse wide.png": "image wide.png is 150x120 pixels, too big to analyse (limit 10,000; set FACSIM_MAX_IMAGE_PIXELS",
        "batch big_set.yaml -o out --dry-run": "expands to 1,200 output files, too many for one set (limit 1,000; "
                                               "set FACSIM_MAX_ITEMS",
    }
    for command, fragment in expected.items():
        _, err = run(command.split(), capsys)
        assert fragment in err, (command, err)


def test_internal_error_exits_1_with_a_report_line(workdir, capsys, monkeypatch):
    import facsim.cli.info as info

    def broken(args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(info, "cmd_aus", broken)
    code, err = run(["aus"], capsys)
    assert code == 1
    assert err.count("\n") == 1 and "please report" in err and "ZeroDivisionError" in err
    with pytest.raises(ZeroDivisionError):
        main(["--debug", "aus"])
