"""Stimulus-set specs and their expansion into items: pure functions, no rendering."""
from __future__ import annotations

import dataclasses
import itertools
import json
from collections import Counter
from pathlib import Path

import pytest
import yaml

from facsim.batch.items import Item, assignments, blind_names, conditions, expand
from facsim.batch.manifest import COLUMNS, Journal, row
from facsim.batch.spec import SpecError, load_spec, spec_from_dict, stimulus_set_schema
from facsim.facs.stimuli import hapfacs_stimuli

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def block(**fields):
    return {"name": "b", "outputs": {"stills": [1]}, **fields}


def spec(*blocks, **top):
    return spec_from_dict({"characters": ["ava"], **top, "blocks": list(blocks)})


# ------------------------------------------------------------ validation ---

def write(tmp_path, text, name="set.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, where, problem", [
    ("blocks:\n  - name: a\n    aus: [12]\n    outptus: {stills: [1]}\n", ":4: blocks[0].outptus",
     "unknown field 'outptus'; did you mean 'outputs'?"),
    ("blocks:\n  - name: a\n    aus: [12, 3]\n    outputs: {stills: [1]}\n", ":3: blocks[0].aus[1]",
     "unknown action unit 3"),
    ("blocks:\n  - name: a\n    aus: [26]\n    sides: [left]\n    outputs: {stills: [1]}\n", ":4: blocks[0].sides[0]",
     "AU26 (Jaw Drop) cannot act on one side"),
    ("blocks:\n  - name: a\n    emotions: [happiness, glee]\n    outputs: {stills: [1]}\n",
     ":3: blocks[0].emotions[1]", "glee"),
    ("characters: [ava, bob]\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n",
     ":1: characters[1]", "unknown character 'bob'"),
    ("views: [front, top]\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n",
     ":1: views[1]", "unknown view 'top'"),
    ("sizes: [[485, 480]]\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {video: true}\n",
     ":1: sizes[0]", "485x480: mp4 videos need even widths and heights"),
    ("blocks:\n  - name: a\n    aus: [1]\n    facs: ['1+2']\n    outputs: {stills: [1]}\n", ":2: blocks[0]",
     "a block needs exactly one of 'aus', 'facs', 'combinations', 'emotions', 'timelines'; got 'aus', 'facs'"),
    ("blocks:\n  - name: a\n    facs: ['1+2']\n    sides: [left]\n    outputs: {stills: [1]}\n", ":2: blocks[0]",
     "'sides' applies only to 'aus' blocks"),
    ("blocks:\n  - name: a\n    facs: ['1+2', '12Q']\n    outputs: {stills: [1]}\n", ":3: blocks[0].facs[1]",
     "12Q"),
    ("blocks:\n  - name: a\n    aus: [1]\n    intensities: [0.5, 150%]\n    outputs: {stills: [1]}\n",
     ":4: blocks[0].intensities[1]", "150%"),
    ("blocks:\n  - name: a\n    aus: [1]\n    outputs: {}\n", ":4: blocks[0].outputs",
     "no outputs: give 'stills', 'video' or 'glb: true'"),
    ("characters: bob\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n", ":1: characters",
     "expected 'all', a list of character names or {random: {n: N, seed: S}}, got 'bob'"),
    ("counterbalance: latin\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n",
     ":1: counterbalance", "expected 'full', 'latin_square' or {latin_square: {lists: N}}"),
    ("blocks:\n  - name: a\n    aus: [1]\n    outputs: {video: {onset: -1}}\n",
     ":4: blocks[0].outputs.video", "video"),
    ("characters: [ava]\ncounterbalance: {latin_square: {lists: 2}}\nblocks:\n  - name: a\n    aus: [1]\n"
     "    outputs: {stills: [1]}\n", ":2: counterbalance.latin_square.lists", "2 lists need at least 2 characters"),
    ("blocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n  - name: a\n    aus: [2]\n"
     "    outputs: {stills: [1]}\n", ":5: blocks[1].name", "block name 'a' is used twice"),
    ("blocks:\n  - name: a\n    timelines: [missing.yaml]\n    outputs: {video: true}\n",
     ":3: blocks[0].timelines[0]", "no timeline file"),
    ("body: tshirt\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n", ":1: body",
     "body must be one of crewneck, none, got 'tshirt'"),
    ("body: [none]\nblocks:\n  - name: a\n    aus: [1]\n    outputs: {stills: [1]}\n", ":1: body",
     "expected a string"),
    ("blocks: [\n", ":2", "malformed YAML"),
    ("", "", "expected a mapping with 'blocks' at the top level, got nothing (the file is empty)"),
])
def test_errors_name_the_file_line_and_field(tmp_path, text, where, problem):
    path = write(tmp_path, text)
    with pytest.raises(SpecError) as info:
        load_spec(path)
    message = str(info.value)
    assert message.startswith(f"{path}{where}"), message
    assert problem in message


def test_schema_is_valid_draft_2020_12_and_documents_every_block_field():
    from jsonschema import Draft202012Validator

    schema = stimulus_set_schema()
    Draft202012Validator.check_schema(schema)
    fields = set(schema["$defs"]["block"]["properties"])
    assert {"aus", "sides", "facs", "combinations", "emotions", "tables", "timelines", "intensities",
            "outputs"} <= fields


def test_examples_validate_against_the_schema_and_load():
    from jsonschema import Draft202012Validator

    validator = Draft202012Validator(stimulus_set_schema())
    for name in ("quick_set.yaml", "hapfacs_validation.yaml"):
        data = yaml.safe_load((EXAMPLES / name).read_text())
        assert not list(validator.iter_errors(data)), name
        load_spec(EXAMPLES / name)


def test_a_timeline_error_is_reported_under_the_spec_field(tmp_path):
    write(tmp_path, "tracks:\n  - au: 12\n    start: 1\n    end: 0.5\n", "bad.yaml")
    path = write(tmp_path, "blocks:\n  - name: a\n    timelines: [bad.yaml]\n    outputs: {video: true}\n")
    with pytest.raises(SpecError, match=r"set.yaml:3: blocks\[0\].timelines\[0\]: timeline 'bad.yaml': .*end"):
        load_spec(path)


# ------------------------------------------------------------- expansion ---

def test_the_body_under_the_head_reaches_every_item():
    # As `--body` on the rendering commands: the crewneck unless the spec says otherwise.
    assert {it.body for it in expand(spec(block(aus=[12])))} == {"crewneck"}
    items = expand(spec(block(aus=[12], outputs={"stills": [1], "video": True, "glb": True}), body="none"))
    assert {it.kind for it in items} == {"still", "video", "glb"}
    assert {it.body for it in items} == {"none"}


def test_full_design_crosses_everything_with_every_character():
    s = spec(block(aus=[1, 12], sides=["both", "left"], intensities=[0.5, 1.0],
                   outputs={"stills": [0.3, 1], "video": True, "glb": True}),
             characters=["ava", "liam"], views=["front", "profile-left"], sizes=[64])
    items = expand(s)
    conditions_ = 2 * 2 * 2 * 2          # AUs × sides × intensities × views
    per_condition = 2 + 1                 # stills + video
    glbs = 2 * 2 * 2                      # a glb per AU × side × intensity (views do not change a glb)
    assert len(items) == 2 * (conditions_ * per_condition + glbs)
    assert Counter(it.character for it in items) == {"ava": len(items) // 2, "liam": len(items) // 2}
    keys = [it.key for it in items]
    assert keys == sorted(keys) and len(set(keys)) == len(keys)


def test_levels_durations_and_labels_are_what_the_files_show():
    s = spec(block(aus=[12], sides=["left"], intensities=["50%"], outputs={"stills": [0.3, 0.6], "video": True}))
    still_low, still_high, video = expand(s)
    assert (still_low.intensity, still_high.intensity, video.intensity) == (0.15, 0.3, 0.5)
    assert still_low.file == "b/ava/AU12L_i015.png" and video.file == "b/ava/AU12L_i050.mp4"
    assert still_low.stimulus.facs == "L12" and still_low.aus == (12,)
    assert video.duration == 3.0 and video.fps == 30 and (video.onset, video.apex, video.offset) == (1, 1, 1)
    assert still_low.duration == 0


def test_emotions_carry_their_preset_and_aus():
    s = spec(block(emotions=["happiness", "surprise"], tables=["hapfacs", "emfacs"]))
    items = expand(s)
    assert [it.stimulus.label for it in items] == ["happiness-emfacs", "happiness-hapfacs", "surprise-emfacs",
                                                   "surprise-hapfacs"]
    happy = items[1]
    assert happy.stimulus.emotion == "happiness" and happy.stimulus.table == "hapfacs"
    assert {6, 12} <= set(happy.aus)


def test_all_emotions_and_all_characters():
    from facsim.facs.emotions import emotion_names
    from facsim.head.character import preset_names

    s = spec_from_dict({"characters": "all", "blocks": [block(emotions="all")]})
    assert len(expand(s)) == len(preset_names()) * len(emotion_names())


def test_hapfacs_tables_are_data():
    table = hapfacs_stimuli()
    assert len(table["single_aus"]) == 49 == len(set(table["single_aus"]))
    assert len(table["combinations"]) == 54 and "1+2+4+5+20+25+26" in table["combinations"]


def test_random_characters_are_seeded_and_distinct():
    def cast(seed, n=5):
        s = spec_from_dict({"characters": {"random": {"n": n, "seed": seed}}, "blocks": [block(aus=[1])]})
        return s.blocks[0].characters

    assert cast(1) == cast(1) != cast(2)
    assert len(set(cast(1, 40))) == 40 and cast(1, 40)[:5] == cast(1)
    assert all(name.startswith("random:") for name in cast(1))


def test_timeline_blocks_take_their_own_timing(tmp_path):
    (tmp_path / "blink.yaml").write_text("fps: 25\ntracks:\n  - au: 45\n    start: 0.5\n    end: 1.5\n")
    path = write(tmp_path, "blocks:\n  - name: t\n    timelines: [blink.yaml]\n    outputs: {video: true, glb: true}\n")
    video, glb = sorted(expand(load_spec(path)), key=lambda it: it.kind, reverse=True)
    assert video.kind == "video" and video.duration == 1.5 and video.fps == 25 and video.aus == (45,)
    assert video.file == "t/ava/blink.mp4"
    assert glb.kind == "glb" and glb.file == "t/ava/blink.glb"


def test_colliding_names_are_refused():
    s = spec(block(aus=[1], intensities=[0.5, 1.0], outputs={"stills": [0.5, 1.0]}))
    with pytest.raises(SpecError, match=r"blocks\[0\]: two outputs would both be 'b/ava/AU01_i050.png'"):
        expand(s)


def test_expansion_is_pure_and_deterministic():
    data = yaml.safe_load((EXAMPLES / "hapfacs_validation.yaml").read_text())
    first = expand(spec_from_dict(data))
    shuffled = dict(reversed(list(data.items())))  # key order of the YAML does not matter
    assert expand(spec_from_dict(shuffled)) == first
    assert all(isinstance(it, Item) for it in first)
    with pytest.raises(dataclasses.FrozenInstanceError):
        first[0].file = "x.png"


# ------------------------------------------------------- counterbalancing ---

def latin(n_conditions, characters, lists=1, seed=0):
    codes = [1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 24, 25, 26][:n_conditions]
    return spec(block(aus=codes), characters=characters,
                counterbalance={"latin_square": {"lists": lists}}, seed=seed)


@pytest.mark.parametrize("n_conditions, n_characters", [(17, 8), (8, 8), (5, 3), (3, 4)])
def test_latin_square_gives_each_character_an_equal_share(n_conditions, n_characters):
    chars = ["ava", "emma", "liam", "noah", "amara", "zola", "kwame", "tunde"][:n_characters]
    items = expand(latin(n_conditions, chars))
    assert len(items) == n_conditions  # each condition once, on one character
    counts = Counter(it.character for it in items)
    assert max(counts.values()) - min(counts.get(c, 0) for c in chars) <= 1


def test_latin_square_lists_rotate_characters_over_conditions():
    chars = ["ava", "emma", "liam", "noah"]
    items = expand(latin(6, chars, lists=4))
    by_condition = {}
    for it in items:
        by_condition.setdefault(it.stimulus.label, []).append((it.list, it.character))
    for shown in by_condition.values():  # with as many lists as characters: every character once
        assert sorted(c for _, c in shown) == sorted(chars) and sorted(k for k, _ in shown) == [1, 2, 3, 4]
    for k in range(1, 5):
        counts = Counter(it.character for it in items if it.list == k)
        assert max(counts.values()) - min(counts.values()) <= 1
    assert all(it.file.startswith(f"b/list{it.list}/") for it in items)


def test_latin_square_order_depends_on_the_seed_only():
    def cast(seed):
        return {it.stimulus.label: it.character for it in expand(latin(8, ["ava", "emma", "liam", "noah"], seed=seed))}

    assert cast(1) == cast(1)
    assert any(cast(1) != cast(s) for s in range(2, 6))


def test_latin_square_balance_holds_over_blocks():
    s = spec_from_dict(yaml.safe_load((EXAMPLES / "hapfacs_validation.yaml").read_text()))
    videos = Counter(it.character for it in expand(s) if it.kind == "video")
    assert len(videos) == 8 and max(videos.values()) - min(videos.values()) <= 1
    for b_index, b in enumerate(s.blocks):
        cast = Counter(c for _, c, _ in assignments(b, b_index, method="latin_square", lists=1, seed=s.seed))
        assert max(cast.values()) - min(cast.values()) <= 1


def test_full_counterbalance_shows_each_condition_on_each_identity_equally_often():
    s = spec(block(aus=[1, 2], intensities=[0.5, 1]), characters=["ava", "liam", "zola"])
    pairs = Counter((c, cond) for _, c, cond in assignments(s.blocks[0], 0, method="full", lists=1, seed=0))
    assert set(pairs.values()) == {1} and len(pairs) == 3 * len(conditions(s.blocks[0]))


# ----------------------------------------------------------------- naming ---

def test_blind_names_hide_the_condition_and_follow_the_seed():
    b = block(aus=[1, 12], outputs={"stills": [0.5, 1], "video": True})
    blind = expand(spec(b, naming={"style": "blind", "key": "secret.csv"}, seed=4))
    assert all(it.file.startswith("stimuli/") and "AU" not in it.file and "ava" not in it.file for it in blind)
    assert len({it.file for it in blind}) == len(blind)
    assert [it.file for it in expand(spec(b, naming="blind", seed=4))] == [it.file for it in blind]
    assert [it.file for it in expand(spec(b, naming="blind", seed=5))] != [it.file for it in blind]
    readable = expand(spec(b, seed=4))
    assert [it.key for it in readable] == [it.key for it in blind]  # same set, other names
    assert {it.file.rsplit(".", 1)[1] for it in blind} == {"png", "mp4"}


def test_blind_names_do_not_depend_on_the_order_keys_arrive():
    keys = [f"b/ava/AU{i:02d}_i100.png" for i in range(30)]
    assert blind_names(keys, 1) == blind_names(list(reversed(keys)), 1)


# ----------------------------------------------------- spec hash, manifest ---

def test_spec_hash_follows_the_spec_and_its_timeline_files(tmp_path):
    (tmp_path / "t.yaml").write_text("tracks:\n  - au: 12\n    start: 0\n    end: 1\n")
    text = "blocks:\n  - name: t\n    timelines: [t.yaml]\n    outputs: {video: true}\n"
    path = write(tmp_path, text)
    first = load_spec(path).spec_hash
    assert load_spec(path).spec_hash == first
    (tmp_path / "t.yaml").write_text("tracks:\n  - au: 12\n    start: 0\n    end: 2\n")
    assert load_spec(path).spec_hash != first
    write(tmp_path, text.replace("video: true", "video: {fps: 25}"))
    assert load_spec(path).spec_hash not in (first,)


def test_manifest_row_has_every_column_as_text():
    item = expand(spec(block(emotions=["happiness"], intensities=[0.5], outputs={"video": True})))[0]
    r = row(item, {"checksum": "ab" * 32, "bytes": 123})
    assert list(r) == list(COLUMNS) and all(isinstance(v, str) for v in r.values())
    assert (r["emotion"], r["intensity"], r["duration"], r["fps"], r["aus"]) == ("happiness", "0.5", "3", "30",
                                                                               "6 12 25")


def test_journal_ignores_and_cuts_a_torn_last_line(tmp_path):
    journal = Journal(tmp_path)
    journal.append("a", "a.png", "00", 1)
    journal.append("b", "b.png", "11", 2)
    journal.close()
    with open(journal.path, "ab") as fh:
        fh.write(b'{"key": "c", "file": "c.pn')  # killed mid-line
    again = Journal(tmp_path)
    assert set(again.load()) == {"a", "b"}
    again.append("c", "c.png", "22", 3)
    again.close()
    lines = journal.path.read_text().splitlines()
    assert [json.loads(line)["key"] for line in lines] == ["a", "b", "c"]


def test_items_pickle_for_workers():
    import pickle

    items = expand(spec(block(aus=[1], outputs={"stills": [1], "video": True})))
    assert pickle.loads(pickle.dumps(items)) == items
    assert all(hash(it) == hash(pickle.loads(pickle.dumps(it))) for it in itertools.islice(items, 2))


def test_progress_line_gives_counts_rate_and_eta():
    import io as _io

    from facsim.batch.run import Progress

    stream = _io.StringIO()
    bar = Progress(100, 40, stream=stream)
    bar.start -= 10.0  # 10 s ago
    bar.update(63)     # not a tenth of the 60 to make: a log gets no line
    assert stream.getvalue() == ""
    bar.update(64)     # 24 new items in 10 s: 2.4 items/s, 36 left → 15 s
    line = bar.text(now=bar.start + 10.0)
    assert "64/100 items, 40 resumed, 2.40 items/s, ETA 0:15" in line
    assert stream.getvalue().count("\n") == 1  # not a terminal: whole lines, for logs
