"""The kit's description: the shipped kit loads, answers the General MIDI keys once each, sets each piece's
head angle from its h, is laid out as drummers set up; a bad kit file is one error naming the piece and field."""

import copy
import math
import re
import tomllib

import mido
import pytest

from _cli import assert_one_line_error, run_process
from drumstroke.design import Setup
from drumstroke.errors import ParameterError
from drumstroke.formats.toml import write_toml
from drumstroke.kit.pieces import DEFAULT_KIT, Kit, Piece, default_kit, read_kit, write_kit
from drumstroke.model import Stick
from drumstroke.stroke import simulate

KIT = default_kit()
DATA = tomllib.loads(DEFAULT_KIT.read_text(encoding="utf-8"))

GENERAL_MIDI = {  # the General MIDI percussion keys of a five-piece kit with hi-hat, ride and crash
    35: "kick", 36: "kick", 37: "snare", 38: "snare", 40: "snare", 42: "hihat", 44: "hihat", 46: "hihat",
    41: "floor-tom", 43: "floor-tom", 45: "tom2", 47: "tom2", 48: "tom1", 50: "tom1", 49: "crash", 57: "crash",
    51: "ride", 59: "ride", 53: "ride-bell",
}
HALF_OPEN = 23
"""The shipped kit's key for the half-open hi-hat: General MIDI has none, so one below its percussion keys (35-81)."""


def test_the_default_kit_loads_with_its_pieces_and_limbs():
    assert [p.name for p in KIT.pieces] == ["snare", "kick", "hihat", "tom1", "tom2", "floor-tom", "ride",
                                          "ride-bell", "crash"]
    assert KIT.hands == ("right", "left") and KIT.feet == ("right-foot", "left-foot")
    assert set(KIT.limbs["right"]) == set(KIT.limbs["left"]) == {"yaw", "lift"}
    assert KIT.limbs["right-foot"] == KIT.limbs["left-foot"] == {}


def test_every_default_key_maps_to_one_piece():
    assert set(KIT.keys) == set(GENERAL_MIDI) | {HALF_OPEN} and HALF_OPEN < min(GENERAL_MIDI)
    for key, name in (GENERAL_MIDI | {HALF_OPEN: "hihat"}).items():
        piece, _ = KIT.piece_for_key(key)
        assert piece.name == name
        assert sum(key in p.keys for p in KIT.pieces) == 1
    assert [KIT.piece_for_key(key)[1] for key in (42, HALF_OPEN, 46, 44)] == ["closed", "half", "open", "pedal"]
    assert KIT.piece_for_key(38)[1] is None
    for unanswered in (34, 39, 52, 55, 81, 127, True, "38"):
        assert KIT.piece_for_key(unanswered) is None


def test_the_feet_play_the_kick_and_the_hi_hats_pedal_the_hands_the_rest():
    hihat = KIT.piece("hihat")
    assert KIT.piece("kick").limbs_for() == ("right-foot",)
    assert hihat.limbs_for("pedal") == ("left-foot",)
    assert hihat.limbs_for("closed") == hihat.limbs_for("half") == hihat.limbs_for("open") == ("right", "left")
    assert (KIT.piece("kick").pedal, hihat.pedal) == ("kick", "hihat")


@pytest.mark.parametrize("name", [p.name for p in KIT.pieces if p.hands])
def test_each_pieces_setup_meets_it_at_minus_asin_h_over_x(name):
    piece = KIT.piece(name)
    h = DATA["pieces"][name]["height"]
    base = Setup(model="geometry")
    setup = piece.setup(base)
    assert setup.head == pytest.approx(-math.asin(h / 0.27), rel=0, abs=1e-15)
    assert setup.stick.pivot_height == h and setup.stick.pivot_to_tip == base.stick.pivot_to_tip
    assert setup.cor == DATA["pieces"][name]["cor"] and setup.model == "geometry"
    assert setup.limits.theta_low == setup.head  # the joint's lowest angle is this piece's surface
    assert setup.moves == base.moves.within(setup.limits) and setup.forces == base.forces  # moves kept above it too
    assert setup.moves.theta_low == setup.head and setup.moves.max_speed == base.moves.max_speed


@pytest.mark.parametrize("state", ["closed", "half", "open"])
def test_a_stick_dropped_on_each_hi_hat_state_bounces_with_that_states_c(state):
    """Each state's c and h as the file gives them (the closed hat's at the piece's level), and a stick let fall
    on that state's Setup, gravity alone, rebounds at c times its landing speed: the exact solver's flights are
    conservative, so the second landing's speed over the first's is c."""
    table = DATA["pieces"]["hihat"]
    given = table["states"][state]
    c, h = given.get("cor", table["cor"]), given.get("height", table["height"])
    setup = KIT.piece("hihat").setup(Setup(), state=state)
    assert (setup.cor, setup.stick.pivot_height) == (c, h)
    assert setup.head == pytest.approx(-math.asin(h / 0.27), rel=0, abs=1e-15) == setup.limits.theta_low
    stroke = simulate(theta0=0.3, omega0=0.0, t_end=1.0, cor=setup.cor, stick=setup.stick, model=setup.model)
    first, second = stroke.impacts.omega[:2]
    assert second / first == pytest.approx(c, rel=1e-9)
    landed = stroke.state(stroke.impacts.t[:1])[0]
    assert landed[0] == pytest.approx(setup.head, rel=0, abs=1e-12)  # on this state's surface


def test_the_hi_hat_gives_back_less_the_looser_its_plates():
    hihat = KIT.piece("hihat")
    closed, half, opened = (hihat.surface(state) for state in ("closed", "half", "open"))
    assert closed.cor > half.cor > opened.cor > KIT.piece("crash").cor  # still held at its centre by the clutch
    assert closed.height == half.height == opened.height  # one surface for the hands' moves (default.toml says why)
    assert hihat.surface() == closed and hihat.setup(Setup()) == hihat.setup(Setup(), state="closed")


def test_a_state_is_asked_of_a_piece_that_has_it():
    with pytest.raises(ParameterError, match=r"state must be None or one of the states a hand plays on "
                                             r"pieces\.hihat \(closed, half, open\), got 'pedal'"):
        KIT.piece("hihat").setup(Setup(), state="pedal")
    with pytest.raises(ParameterError, match=r"pieces\.snare \(none: it has no states\), got 'open'"):
        KIT.piece("snare").setup(Setup(), state="open")
    with pytest.raises(ParameterError, match=r"pieces\.kick is played by right-foot, not by a stick"):
        KIT.piece("kick").setup(Setup(), state="closed")


def test_the_snare_is_the_papers_stick_and_head():
    setup = KIT.piece("snare").setup(Setup())
    assert setup.head == Stick().theta_max and setup.cor == Setup().cor


def test_a_foot_piece_has_no_stick():
    with pytest.raises(ParameterError, match="pieces.kick is played by right-foot, not by a stick"):
        KIT.piece("kick").setup(Setup())
    with pytest.raises(ParameterError, match="base must be a drumstroke.design.Setup"):
        KIT.piece("snare").setup(Stick())


def test_cymbals_give_back_less_than_heads_and_sit_higher():
    cymbals = [p for p in KIT.pieces if p.kind in ("cymbal", "hihat")]
    drums = [p for p in KIT.pieces if p.kind == "membrane"]
    assert max(p.cor for p in cymbals) < min(p.cor for p in drums)
    assert max(p.height for p in cymbals) < min(p.height for p in drums)  # the stick meets them flatter
    assert min(p.place["lift"] for p in cymbals) > max(p.place["lift"] for p in drums)


def test_the_layout_is_a_right_handed_drummers():
    yaw = {p.name: p.place["yaw"] for p in KIT.pieces if p.hands}  # positive: to the drummer's left
    assert yaw["hihat"] > yaw["crash"] > yaw["snare"] > yaw["tom1"] > yaw["tom2"] > yaw["floor-tom"] > yaw["ride"]
    assert KIT.piece("crash").place["lift"] == max(p.place["lift"] for p in KIT.pieces if p.hands)
    assert [p.role for p in KIT.pieces if p.role == "time"] == ["time"] * 3  # hi-hat, ride, bell
    assert KIT.piece("snare").role == "backbeat" and KIT.piece("crash").role == "accent"


def test_the_default_kit_round_trips_through_toml(tmp_path):
    path = tmp_path / "kit.toml"
    write_kit(path, KIT)
    again = read_kit(path)
    assert again == KIT
    assert tomllib.loads(path.read_text(encoding="utf-8")) == KIT.to_dict()


def test_a_kit_file_of_the_older_form_reads_with_the_pieces_c_and_h_in_every_state(tmp_path):
    """A kit written before the hi-hat's states had their own c and h (``keys = {closed = 42, ...}``) reads as it
    did: each state the piece's c and h; written again, it is in the states' form, and reads back the same."""
    data = copy.deepcopy(DATA)
    hihat = data["pieces"]["hihat"]
    hihat.pop("states")
    hihat["keys"] = {"closed": 42, "open": 46, "pedal": 44}
    old = tmp_path / "old.toml"
    write_toml(old, data)
    piece = read_kit(old).piece("hihat")
    assert piece.keys == (42, 46, 44) and piece.states == {42: "closed", 46: "open", 44: "pedal"}
    assert dict(piece.surfaces) == {"closed": (0.55, 0.05), "open": (0.55, 0.05)}
    again = tmp_path / "again.toml"
    write_kit(again, read_kit(old))
    assert tomllib.loads(again.read_text(encoding="utf-8"))["pieces"]["hihat"]["states"] == {
        "closed": {"keys": 42}, "open": {"keys": 46}, "pedal": {"keys": 44}}
    assert read_kit(again) == read_kit(old)


def test_a_hi_hat_with_a_state_of_several_keys_and_its_own_numbers_round_trips(tmp_path):
    data = copy.deepcopy(DATA)
    data["pieces"]["hihat"]["states"] = {"open": {"keys": [46, 26], "cor": 0.3}, "closed": {"keys": [42, 22]},
                                         "pedal": {"keys": 44}}
    path = tmp_path / "kit.toml"
    write_toml(path, data)
    kit = read_kit(path)
    hihat = kit.piece("hihat")
    assert hihat.keys == (46, 26, 42, 22, 44) and hihat.state(26) == "open" and hihat.state(22) == "closed"
    assert hihat.surfaces == {"closed": (0.55, 0.05), "open": (0.3, 0.05)}
    write_kit(tmp_path / "again.toml", kit)
    assert read_kit(tmp_path / "again.toml") == kit


def bad_kit(tmp_path, change):
    """The default kit's data with ``change`` applied, written to a file."""
    data = copy.deepcopy(DATA)
    change(data)
    path = tmp_path / "bad.toml"
    write_toml(path, data)
    return path


def _set(table, key, value):
    table[key] = value


def _hihat_keys(data, keys):
    """The hi-hat's keys in the older form, ``keys`` (a list, or a table of state to key), instead of its states."""
    hihat = data["pieces"]["hihat"]
    hihat.pop("states")
    hihat["keys"] = keys


BAD = {
    "out of reach": (lambda d: _set(d["pieces"]["crash"]["place"], "yaw", 1.2),
                     (r"pieces\.crash\.place\.yaw = 1\.2 rad is out of the right hand's reach: its yaw joint "
                      r"moves in \[-1\.3, 1\] rad")),
    "two in one place": (lambda d: _set(d["pieces"]["tom2"], "place", {"yaw": 0.005, "lift": 0.195}),
                         r"pieces\.tom2\.place is pieces\.tom1's place for the right hand"),
    "a key on two pieces": (lambda d: _set(d["pieces"]["tom2"], "keys", [45, 50]),
                            r"pieces\.tom2\.keys: key 50 is also pieces\.tom1's"),
    "c above 1": (lambda d: _set(d["pieces"]["snare"], "cor", 1.2), r"pieces\.snare\.cor must be in \[0, 1\)"),
    "c of 1": (lambda d: _set(d["pieces"]["snare"], "cor", 1.0), r"pieces\.snare\.cor must be in \[0, 1\)"),
    "c below 0": (lambda d: _set(d["pieces"]["ride"], "cor", -0.1), r"pieces\.ride\.cor must be in \[0, 1\)"),
    "h at x": (lambda d: _set(d["pieces"]["crash"], "height", 0.27),
               r"pieces\.crash\.height must be in \(0, 0\.27\) m"),
    "h of 0": (lambda d: _set(d["pieces"]["crash"], "height", 0.0), r"pieces\.crash\.height must be in \(0, 10\) m"),
    "h negative": (lambda d: _set(d["pieces"]["hihat"], "height", -0.05), r"pieces\.hihat\.height must be in"),
    "unknown limb": (lambda d: _set(d["pieces"]["snare"], "limbs", ["right", "third-hand"]),
                     (r"pieces\.snare\.limbs must be one of 'right', 'left', 'right-foot', 'left-foot', "
                      r"got 'third-hand'")),
    "a limb the kit lacks": (lambda d: d["limbs"].pop("left-foot"),
                             r"pieces\.hihat\.limbs names 'left-foot', not a limb of the kit"),
    "missing c": (lambda d: d["pieces"]["ride"].pop("cor"), r"pieces\.ride\.cor is missing"),
    "missing keys": (lambda d: d["pieces"]["ride"].pop("keys"), r"pieces\.ride\.keys is missing"),
    "missing h": (lambda d: d["pieces"]["tom1"].pop("height"), r"pieces\.tom1\.height is missing"),
    "missing place": (lambda d: d["pieces"]["tom1"].pop("place"), r"pieces\.tom1\.place\.yaw is missing"),
    "missing joint": (lambda d: d["pieces"]["tom1"]["place"].pop("lift"), r"pieces\.tom1\.place\.lift is missing"),
    "unknown joint": (lambda d: _set(d["pieces"]["tom1"]["place"], "roll", 0.1),
                      r"pieces\.tom1\.place\.roll: the hands have no joint 'roll'"),
    "missing pedal": (lambda d: d["pieces"]["kick"].pop("pedal"), r"pieces\.kick\.pedal is missing"),
    "two pieces on one pedal": (lambda d: _set(d["pieces"]["hihat"], "pedal", "kick") or
                                _set(d["pieces"]["hihat"], "limbs", ["right", "left", "right-foot"]),
                                r"pieces\.hihat\.pedal 'kick' is also pieces\.kick's for the right-foot"),
    "a hi-hat key without a state": (lambda d: _hihat_keys(d, [42, 46, 44]), r"pieces\.hihat\.keys: key 42 has no state"),
    "an unknown state": (lambda d: _hihat_keys(d, {"closed": 42, "loose": 46}),
                         r"pieces\.hihat\.keys\.loose must be one of 'closed', 'half', 'open', 'pedal'"),
    "a key out of MIDI": (lambda d: _set(d["pieces"]["snare"], "keys", [38, 128]),
                          r"pieces\.snare\.keys must be MIDI keys, integers in \[0, 127\], got 128"),
    "a hi-hat key that is not a key": (lambda d: _hihat_keys(d, {"closed": [42, {"a": 1}]}),
                                       r"pieces\.hihat\.keys must be MIDI keys, integers in \[0, 127\], got \{'a': 1\}"),
    "a stick's tip that is not a length": (lambda d: _set(d["stick"], "pivot_to_tip", "long"),
                                           r"stick\.pivot_to_tip must be a number in \(0, 10\] m"),
    "an unknown field": (lambda d: _set(d["pieces"]["snare"], "colour", "red"),
                         r"pieces\.snare has unknown key 'colour'"),
    "an unknown kind": (lambda d: _set(d["pieces"]["snare"], "kind", "gong"), r"pieces\.snare\.kind must be one of"),
    "a joint's bad limit": (lambda d: _set(d["limbs"]["left"]["joints"]["yaw"], "max_speed", 0.0),
                            r"limbs\.left\.joints\.yaw\.max_speed must be in \(0, inf\) rad/s"),
    "a foot with a joint": (lambda d: _set(d["limbs"]["right-foot"], "joints", d["limbs"]["right"]["joints"]),
                            r"limbs\.right-foot\.joints must be empty"),
    "hands without a yaw": (lambda d: d["limbs"]["left"]["joints"].pop("yaw"), r"limbs\.left\.joints\.yaw is missing"),
    "no pieces": (lambda d: d.pop("pieces"), r"pieces is missing"),
    "a state's c of 1": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "cor", 1.0),
                         r"pieces\.hihat\.states\.open\.cor must be in \[0, 1\), got 1\.0"),
    "a state's c below 0": (lambda d: _set(d["pieces"]["hihat"]["states"]["half"], "cor", -0.2),
                            r"pieces\.hihat\.states\.half\.cor must be in \[0, 1\)"),
    "a state's h at x": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "height", 0.27),
                         r"pieces\.hihat\.states\.open\.height must be in \(0, 0\.27\) m"),
    "a state's h of 0": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "height", 0.0),
                         r"pieces\.hihat\.states\.open\.height must be in \(0, 10\) m"),
    "the pedal state with a c": (lambda d: _set(d["pieces"]["hihat"]["states"]["pedal"], "cor", 0.5),
                                 r"pieces\.hihat\.states\.pedal\.cor: the pedal state is the foot's"),
    "an unknown state's table": (lambda d: _set(d["pieces"]["hihat"]["states"], "loose", {"keys": 26}),
                                 r"pieces\.hihat\.states must be one of 'closed', 'half', 'open', 'pedal', got 'loose'"),
    "a state without keys": (lambda d: d["pieces"]["hihat"]["states"]["half"].pop("keys"),
                             r"pieces\.hihat\.states\.half\.keys is missing"),
    "a state's unknown field": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "gap", 0.01),
                                r"pieces\.hihat\.states\.open has unknown key 'gap'"),
    "a key in two states": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "keys", [46, 42]),
                            r"pieces\.hihat\.states names a key twice"),
    "a state's key on another piece": (lambda d: _set(d["pieces"]["hihat"]["states"]["half"], "keys", 38),
                                       r"pieces\.hihat\.keys: key 38 is also pieces\.snare's"),
    "keys and states both": (lambda d: _set(d["pieces"]["hihat"], "keys", [42]),
                             r"pieces\.hihat\.keys: a hi-hat with \[pieces\.hihat\.states\.STATE\] tables gives its keys"),
    "states on a drum": (lambda d: d["pieces"]["snare"].pop("keys") and
                         _set(d["pieces"]["snare"], "states", {"closed": {"keys": 38}}),
                         r"pieces\.snare\.keys: only a hi-hat's keys have states"),
    "a place that is not a number": (lambda d: _set(d["pieces"]["snare"]["place"], "yaw", math.nan),
                                     r"pieces\.snare\.place\.yaw must be a finite number in"),
    "an infinite c": (lambda d: _set(d["pieces"]["tom1"], "cor", math.inf),
                      r"pieces\.tom1\.cor must be a finite number in \[0, 1\), got inf"),
    "a state's h that is not a number": (lambda d: _set(d["pieces"]["hihat"]["states"]["open"], "height", math.nan),
                                         r"pieces\.hihat\.states\.open\.height must be a finite number"),
    "an infinite joint limit": (lambda d: _set(d["limbs"]["right"]["joints"]["lift"], "theta_high", math.inf),
                                r"limbs\.right\.joints\.lift\.theta_high must be a finite number"),
}


@pytest.mark.parametrize("case", BAD)
def test_a_bad_kit_is_one_error_naming_the_file_the_piece_and_the_field(case, tmp_path):
    change, message = BAD[case]
    path = bad_kit(tmp_path, change)
    with pytest.raises(ParameterError, match=rf"^kit '{path}': {message}") as error:
        read_kit(path)
    assert str(error.value).count("\n") == 0


def test_a_byte_order_mark_before_the_kit_is_read_past(tmp_path):
    """A Windows editor may start a UTF-8 file with a byte-order mark: the kit reads as without it."""
    path = tmp_path / "kit.toml"
    path.write_bytes(b"\xef\xbb\xbf" + DEFAULT_KIT.read_bytes())
    assert read_kit(path) == KIT


def test_a_file_that_is_not_toml_is_named(tmp_path):
    path = tmp_path / "kit.toml"
    path.write_text("[pieces.snare\n", encoding="utf-8")
    with pytest.raises(ParameterError, match=rf"kit '{path}' is not valid TOML"):
        read_kit(path)


def test_pieces_and_kits_built_in_python_are_checked_too():
    snare = KIT.piece("snare")
    with pytest.raises(ParameterError, match="piece name must be"):
        Piece("Snare", "membrane", (38,), ("right",), 0.8, height=0.07, place={"yaw": 0.0})
    with pytest.raises(ParameterError, match=r"pieces\.x\.height is only for a piece a hand plays"):
        Piece("x", "kick", (36,), ("right-foot",), 0.5, height=0.07, pedal="kick")
    with pytest.raises(ParameterError, match=r"pieces\.x\.keys: only a hi-hat's keys have states"):
        Piece("x", "membrane", (38,), ("right",), 0.8, height=0.07, place={"yaw": 0.0}, states={38: "open"})
    with pytest.raises(ParameterError, match=r"pieces\.snare appears twice"):
        Kit((snare, snare), KIT.limbs)
    with pytest.raises(ParameterError, match=r"pieces must be a non-empty sequence"):
        Kit((), KIT.limbs)
    with pytest.raises(ParameterError, match=r"limbs must be one of"):
        Kit((snare,), {**KIT.limbs, "tail": {}})
    with pytest.raises(ParameterError, match=r"piece must be one of the kit's pieces"):
        KIT.piece("cowbell")


def test_the_docs_example_kit_is_a_kit(tmp_path):
    """The kit file the documentation shows, field by field, reads as a kit."""
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "kit.md").read_text(encoding="utf-8")
    example = page.split("```toml\n", 1)[1].split("```", 1)[0]
    path = tmp_path / "small.toml"
    path.write_text(example, encoding="utf-8")
    kit = read_kit(path)
    assert [p.name for p in kit.pieces] == ["snare", "hihat", "kick"]
    assert kit.limbs == KIT.limbs and kit.stick == KIT.stick
    for piece in kit.pieces:
        assert piece == KIT.piece(piece.name)


CLI_BAD = ["out of reach", "two in one place", "a key on two pieces", "c above 1", "c below 0", "h at x", "h of 0",
           "a state's h at x", "a state's c of 1", "unknown limb", "a limb the kit lacks", "a place that is not a number",
           "an infinite c"]
"""The bad kits a person is likeliest to write, each as the command sees it."""


def small_song(path):
    """A MIDI file of four drum notes on channel 10 (kick, snare, closed and open hi-hat), 0.25 s apart."""
    track = mido.MidiTrack()
    for key in (36, 38, 42, 46):
        track += [mido.Message("note_on", channel=9, note=key, velocity=100, time=0),
                  mido.Message("note_off", channel=9, note=key, velocity=0, time=240)]
    song = mido.MidiFile(ticks_per_beat=480)
    song.tracks.append(track)
    song.save(path)
    return path


def compose_with(tmp_path, kit):
    """``drumstroke compose SONG.mid --kit KIT --csv --json --audio`` in a subprocess, an older out.csv in place;
    the result and the folder's files (name: bytes) after it."""
    song = small_song(tmp_path / "song.mid")
    out = tmp_path / "out"
    out.mkdir()
    (out / "out.csv").write_bytes(b"t,right.theta\n0,0.1\n")
    result = run_process("compose", song, "--kit", kit, "--csv", out / "out.csv", "--json", out / "out.json",
                         "--audio", out / "out.wav")
    return result, {path.name: path.read_bytes() for path in out.iterdir()}


@pytest.mark.parametrize("case", CLI_BAD)
def test_compose_with_a_bad_kit_is_one_error_and_writes_nothing(case, tmp_path):
    change, message = BAD[case]
    kit = bad_kit(tmp_path, change)
    result, files = compose_with(tmp_path, kit)
    assert_one_line_error(result, f"kit '{kit}': ")
    assert re.search(message, result.stderr), result.stderr
    assert files == {"out.csv": b"t,right.theta\n0,0.1\n"}  # the older CSV untouched, nothing else written


def test_compose_with_a_kit_that_is_not_toml_is_one_error_and_writes_nothing(tmp_path):
    kit = tmp_path / "bad.toml"
    kit.write_bytes(DEFAULT_KIT.read_bytes().replace(b"[pieces.snare]", b"[pieces.snare", 1))
    result, files = compose_with(tmp_path, kit)
    assert_one_line_error(result, f"kit '{kit}' is not valid TOML", "line ")
    assert files == {"out.csv": b"t,right.theta\n0,0.1\n"}


def test_compose_reads_a_kit_that_starts_with_a_byte_order_mark(tmp_path):
    kit = tmp_path / "bom.toml"
    kit.write_bytes(b"\xef\xbb\xbf" + DEFAULT_KIT.read_bytes())
    result, files = compose_with(tmp_path, kit)
    assert result.returncode == 0, result.stderr
    assert "played 4 of 4 notes on the kit" in result.stdout
    assert set(files) == {"out.csv", "out.json", "out.wav"} and files["out.csv"].startswith(b"t,right.yaw")
