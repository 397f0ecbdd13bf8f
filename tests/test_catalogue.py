"""facsim.facs.catalogue: the FACS table and the intensity tables."""
import pytest

from facsim.facs.catalogue import (INTENSITY_TABLES, KINDS, REGIONS, ActionUnitInfo, UnknownActionUnitError,
                              catalogue, describe_table, info, intensity_of, letter_of)

ACTION_CODES = [1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26,
                27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 41, 42, 43, 44, 45, 46]
HEAD_CODES = [51, 52, 53, 54, 55, 56, 57, 58]
EYE_CODES = [61, 62, 63, 64, 65, 66]
GROSS_CODES = [40, 50, 80, 81, 82, 84, 85, 91, 92, 97, 98]
VISIBILITY_CODES = [70, 71, 72, 73, 74]
KIND_OF = {**dict.fromkeys(ACTION_CODES, "action"), **dict.fromkeys(HEAD_CODES, "head"),
           **dict.fromkeys(EYE_CODES, "eye"), **dict.fromkeys(GROSS_CODES, "gross"),
           **dict.fromkeys(VISIBILITY_CODES, "visibility")}


def test_catalogue_is_exactly_the_facs_list():
    assert sorted(catalogue()) == sorted(KIND_OF)
    assert list(catalogue()) == sorted(catalogue())          # ascending
    assert 3 not in catalogue() and 0 not in catalogue()


@pytest.mark.parametrize("code", sorted(KIND_OF))
def test_entry_fields(code):
    unit = catalogue()[code]
    assert isinstance(unit, ActionUnitInfo) and unit.code == code
    assert unit.kind == KIND_OF[code]
    assert unit.name and unit.name[0].isupper()
    assert unit.region in REGIONS and unit.kind in KINDS
    assert isinstance(unit.muscles, tuple) and all(isinstance(m, str) and m for m in unit.muscles)
    assert unit.description.endswith(".")
    assert unit.rendered == (unit.kind not in ("gross", "visibility"))
    assert unit.label == f"AU{code}"


def test_regions_match_kinds():
    expected = {"head": {"head"}, "eye": {"eyes"}, "gross": {"gross behaviour"},
                "visibility": {"visibility"}, "action": {"upper face", "lower face"}}
    for unit in catalogue().values():
        assert unit.region in expected[unit.kind], unit


@pytest.mark.parametrize("code, name", [
    (1, "Inner Brow Raiser"), (4, "Brow Lowerer"), (8, "Lips Toward Each Other"), (12, "Lip Corner Puller"),
    (26, "Jaw Drop"), (42, "Inner Eyebrow Lowerer"), (46, "Wink"), (53, "Head Up"), (65, "Walleye"),
    (66, "Cross-eye"), (40, "Sniff"), (98, "Fast Up-Down Look"), (74, "Unscorable"),
])
def test_known_names(code, name):
    assert info(code).name == name


def test_muscles_example():
    assert info(1).muscles == ("frontalis, pars medialis",)


@pytest.mark.parametrize("code", [12, 14, 1, 2, 6, 46])
def test_can_be_unilateral(code):
    assert info(code).unilateral


@pytest.mark.parametrize("code", [25, 26, 27, 29, 45, *HEAD_CODES, *EYE_CODES, *GROSS_CODES, *VISIBILITY_CODES])
def test_cannot_be_unilateral(code):
    assert not info(code).unilateral


@pytest.mark.parametrize("query", [12, "12", "AU12", "au12", " AU12 "])
def test_info_accepts_int_and_labels(query):
    assert info(query).code == 12


@pytest.mark.parametrize("query", [3, 99, "AU3", "twelve", 12.0, True, None])
def test_info_unknown(query):
    with pytest.raises(UnknownActionUnitError, match=r"unknown action unit .*known codes are 1-2, 4-46"):
        info(query)
    with pytest.raises(KeyError):
        info(query)
    with pytest.raises(ValueError):
        info(query)


def test_catalogue_is_read_only_and_cached():
    cat = catalogue()
    assert cat is catalogue()
    with pytest.raises(TypeError):
        cat[3] = cat[1]
    with pytest.raises(AttributeError):
        cat[1].name = "x"


# ----------------------------------------------------------- intensities ---

def test_intensity_tables_values():
    assert dict(INTENSITY_TABLES["hapfacs"]) == {"A": 0.15, "B": 0.30, "C": 0.55, "D": 0.85, "E": 1.0}
    assert dict(INTENSITY_TABLES["facshuman"]) == {"A": 0.10, "B": 0.20, "C": 0.55, "D": 0.90, "E": 1.0}
    with pytest.raises(TypeError):
        INTENSITY_TABLES["hapfacs"]["A"] = 0.2


@pytest.mark.parametrize("table", sorted(INTENSITY_TABLES))
def test_letter_round_trip(table):
    for letter, value in INTENSITY_TABLES[table].items():
        assert intensity_of(letter, table) == value
        assert intensity_of(letter.lower(), table=table) == value
        assert letter_of(value, table) == letter
    assert letter_of(0.42, table) is None


@pytest.mark.parametrize("call, match", [
    (lambda: intensity_of("F"), "unknown intensity letter 'F'"),
    (lambda: intensity_of("A", table="nope"), "unknown intensity table 'nope'"),
    (lambda: letter_of(0.5, table="nope"), "unknown intensity table 'nope'"),
])
def test_intensity_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# -------------------------------------------------------------- display ---

def test_describe_table_has_engine_columns():
    text = describe_table({"register": {1, 12}, "muscle": {12}})
    lines = text.splitlines()
    assert lines[0].split() == ["AU", "name", "region", "L/R", "rendered", "register", "muscle"]
    assert len(lines) == 1 + len(catalogue())
    row12 = next(line for line in lines if line.startswith("12 "))
    assert row12.split()[-2:] == ["x", "x"]
    row1 = next(line for line in lines if line.startswith("1 "))
    assert row1.split()[-1] == "x" and row1.count(" x") == 1
    row50 = next(line for line in lines if line.startswith("50 "))
    assert row50.split()[-1] == "no"            # not rendered, no engine marks


def test_describe_table_filters_kinds():
    text = describe_table(kinds=["head"])
    assert [line.split()[0] for line in text.splitlines()[1:]] == [str(c) for c in HEAD_CODES]
    with pytest.raises(ValueError, match="kinds must be among"):
        describe_table(kinds=["mouth"])
