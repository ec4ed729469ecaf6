"""Per-group breakdowns of an evaluation (`attitude evaluate --by`): the recordings' groups from
BROAD's trial names or from a column of a table of trials, and the means over each group.

The protocol (BROAD's, and this project's for every dataset): per trial, the RMSE over its
movement samples of the heading and inclination errors (blocks.errors.quaternion_errors);
over trials, their mean (systems.evaluation.evaluate.mean_over), so every trial weighs the same
whatever its length. A group's figure is that mean over the group's trials.
"""
from __future__ import annotations

import csv
import re
from pathlib import Path

BROAD = "broad"  # --by broad: the groups of BROAD's trial names
BROAD_NAME = re.compile(r"^\d+_(undisturbed|disturbed)_(.+?)(?:_[A-Z])?$")
BROAD_GROUPS = ("rotation", "translation", "combined", "tapping", "vibration", "magnet")  # the motion's kind


def broad_group(name: str) -> str | None:
    """A BROAD trial's group from its name ("01_undisturbed_slow_rotation_A" → "undisturbed rotation",
    "28_disturbed_stationary_magnet_A" → "disturbed magnet"); None for another name."""
    match = BROAD_NAME.match(Path(name).stem)
    if not match:
        return None
    kind = next((k for k in BROAD_GROUPS if k in match.group(2)), match.group(2))
    return f"{match.group(1)} {kind}"


def table_groups(path, column: str, key: str = "name") -> dict[str, str]:
    """{trial name: group} from a CSV table of trials: its column key names the recording (its
    file's stem), column the group."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if not rows or key not in rows[0] or column not in rows[0]:
        found = ", ".join(rows[0]) if rows else "no rows"
        raise ValueError(f"--by {path}:{column}: the table needs the columns {key!r} and {column!r}; it has {found}")
    return {Path(row[key]).stem: row[column] for row in rows}


def groups(names, by: str) -> dict[str, str]:
    """{recording name: group} for the names of an evaluation: by "broad" (broad_group) or
    "TABLE.csv:COLUMN" (table_groups); names in no group are left out."""
    if by == BROAD:
        found = {name: broad_group(name) for name in names}
    else:
        path, sep, column = by.rpartition(":")
        if not sep or not path or not column:
            raise ValueError(f"--by takes 'broad' or TABLE.csv:COLUMN, got {by!r}")
        table = table_groups(path, column)
        found = {name: table.get(Path(name).stem) for name in names}
    return {name: group for name, group in found.items() if group}

