"""What a CSV's header says beyond the names: units written after a name ("gyr_x (deg/s)",
"acc_x [g]") or in a units row under it ("s,deg/s,…"), and columns selected by position
("#3", counted from 1 as spreadsheets count them)."""
from __future__ import annotations

import re

from attitude_fmu.systems.recordings.recording import RecordingError

UNIT_WORDS = {  # the words a header writes a unit in (lower case, "µ" as "u", "°" as "deg") → our unit
    "t": {"s": "s", "sec": "s", "seconds": "s", "ms": "ms", "msec": "ms", "us": "us", "usec": "us", "ns": "ns",
          "nsec": "ns"},
    "gyr": {"rad/s": "rad/s", "rad s^-1": "rad/s", "rad/sec": "rad/s", "deg/s": "deg/s", "deg s^-1": "deg/s",
            "deg/sec": "deg/s", "dps": "deg/s", "degree/s": "deg/s", "degrees/s": "deg/s", "mdeg/s": "mdeg/s",
            "mdps": "mdeg/s"},
    "acc": {"m/s^2": "m/s2", "m/s2": "m/s2", "m s^-2": "m/s2", "ms^-2": "m/s2", "m/s/s": "m/s2", "g": "g",
            "mg": "mg"},
    "mag": {"ut": "uT", "microtesla": "uT", "nt": "nT", "g": "G", "gauss": "G", "mg": "mG", "mgauss": "mG",
            "milligauss": "mG"},
}
FLAGS = {"t": ("--t-unit", "time stamps"), "gyr": ("--gyr-unit", "gyro"), "acc": ("--acc-unit", "accelerometer"),
         "mag": ("--mag-unit", "magnetometer")}
WITH_UNIT = re.compile(r"^(.*?)\s*[(\[]([^()\[\]]*)[)\]]$")  # NAME (UNIT) or NAME [UNIT]
POSITION = re.compile(r"^#(\d+)$")


def quantity(column: str) -> str | None:
    """t, gyr, acc or mag: what one of our columns holds (None for the others)."""
    kind = column.split("_")[0]
    return kind if kind in UNIT_WORDS else None


def unit_of(kind: str, text: str) -> str | None:
    """Our unit of a quantity (t, gyr, acc, mag) written as text ("(deg/s)", "m s^-2", "°/s",
    "µT"), None where text is none of UNIT_WORDS."""
    word = text.strip().strip("()[]").strip().replace("µ", "u").replace("μ", "u").replace("°", "deg")
    word = re.sub(r"\s*([*·/])\s*", r"\1", word.replace("²", "^2").replace("⁻¹", "^-1").replace("⁻²", "^-2"))
    word = re.sub(r"\s+", " ", word.replace("*", " ").replace("·", " ")).lower()
    return UNIT_WORDS[kind].get(word)


def without_units(header: list[str], known) -> tuple[list[str], dict]:
    """(header with "NAME (UNIT)" read as NAME where NAME is one of known and UNIT a unit of
    its quantity, {position: the text it was}): the units are then those of written_units()."""
    out, written = list(header), {}
    for k, name in enumerate(header):
        match = WITH_UNIT.match(name)
        if match and match[1] in known and quantity(match[1]) and unit_of(quantity(match[1]), match[2]):
            out[k], written[k] = match[1], name
    return out, written


def written_units(header: list[str], original: list[str], label_rows: list[list[str]]) -> dict:
    """{quantity: (unit, where it is written)} of our columns in header (after renaming) whose
    name in the file (original, same positions) ends in a unit or whose field in a units row
    (label_rows) is one; a quantity whose columns say different units is left out."""
    found = {}
    for k, name in enumerate(header):
        kind = quantity(name)
        if kind is None:
            continue
        match = WITH_UNIT.match(original[k])
        texts = ([(match[2], repr(original[k]))] if match else []) + [
            (row[k], f"{row[k].strip()!r} under column #{k + 1}") for row in label_rows if k < len(row)]
        for text, where in texts:
            unit = unit_of(kind, text)
            if unit:
                found.setdefault(kind, []).append((unit, where))
                break
    return {kind: (said[0][0], ", ".join(w for _, w in said[:3]) + (", …" if len(said) > 3 else ""))
            for kind, said in found.items() if len({u for u, _ in said}) == 1}


def check_units(path, name: str, written: dict, used: dict) -> list[str]:
    """Against the units written in the header (written_units()), the units the file is read in
    (used: {quantity: (unit, given by a flag?)}): a unit not given that the header
    contradicts is refused with the flag to give; one given is kept, and noted."""
    notes = []
    for kind, (unit, where) in written.items():
        read, given = used[kind]
        if unit == read:
            continue
        flag, what = FLAGS[kind]
        if not given:
            raise RecordingError(f"{path}: the header gives the {what} in {unit} ({where}), read in {read} by default: "
                                 f"pass {flag} {unit} (or {flag} {read} to read it as {read})")
        notes.append(f"{name}: the header gives the {what} in {unit} ({where}); read in {read} as {flag} says")
    return notes


def positions(path, header: list[str], columns: dict) -> dict:
    """{our name: its position in header} of the --column map ({ours: the file's name, or
    "#N", the N-th column counted from 1}); a name the header has more than once, a
    position beyond it and one column given two names are refused, showing the header
    numbered."""
    absent = [theirs for theirs in columns.values() if not POSITION.match(theirs) and theirs not in header]
    if absent:
        raise RecordingError(f"{path}: --column names {', '.join(absent)}, not in the header ({shown(header)})")
    placed = {}
    for ours, theirs in columns.items():
        match = POSITION.match(theirs)
        if match:
            k = int(match[1]) - 1
            if not 0 <= k < len(header):
                raise RecordingError(f"{path}: --column {ours}={theirs}: the file has {len(header)} columns, counted "
                                     f"from #1: {numbered(header)}")
        else:
            where = [k for k, h in enumerate(header) if h == theirs]
            if len(where) > 1:
                raise RecordingError(f"{path}: --column names {theirs}, which the header has {len(where)} times; "
                                     f"select one by position, e.g. --column {ours}=#{where[0] + 1} "
                                     f"({numbered(header)})")
            k = where[0]
        placed[ours] = k
    twice = sorted({header[k] or f"#{k + 1}" for k in placed.values() if list(placed.values()).count(k) > 1})
    if twice:
        raise RecordingError(f"{path}: --column gives the file's column {', '.join(twice)} more than one name")
    return placed


SHOWN_COLUMNS = 24  # the columns a message shows of a header: a wide file's header is not echoed whole


def numbered(header: list[str]) -> str:
    """The header as "#1 t, #2 gyro, #3 (unnamed), …" (the first SHOWN_COLUMNS, then how many more)."""
    return ", ".join(f"#{k + 1} {h or '(unnamed)'}" for k, h in enumerate(header[:SHOWN_COLUMNS])) + _more(header)


def shown(header: list[str]) -> str:
    """The header as a CSV line shows it, t,gyr_x,… (the first SHOWN_COLUMNS, then how many more)."""
    return ",".join(header[:SHOWN_COLUMNS]) + _more(header)


def _more(header: list[str]) -> str:
    extra = len(header) - SHOWN_COLUMNS
    return f", … and {extra} more of its {len(header)} columns" if extra > 0 else ""
