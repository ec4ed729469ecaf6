"""evaluate --by (systems.evaluation.groups, evaluate.by_group): BROAD's trial names grouped as the
dataset names its trials, a table's column, and each group's mean that of its trials' RMSEs."""
import pytest

from attitude_fmu.systems.evaluation.evaluate import by_group
from attitude_fmu.systems.evaluation.groups import broad_group, groups


@pytest.mark.parametrize("name, group", [
    ("01_undisturbed_slow_rotation_A", "undisturbed rotation"),
    ("04_undisturbed_slow_rotation_with_breaks_A", "undisturbed rotation"),
    ("21_undisturbed_fast_combined", "undisturbed combined"),
    ("26_disturbed_phone_vibration_A", "disturbed vibration"),
    ("/data/32_disturbed_attached_magnet_1cm.mat", "disturbed magnet"),
    ("walk_03", None),
])
def test_broad_names_give_broads_groups(name, group):
    assert broad_group(name) == group


def _table(inclination):
    return {"wiener": {"inclination_rmse_deg": inclination, "heading_rmse_deg": 2 * inclination,
                       "total_rmse_deg": 3 * inclination}}


def test_group_means_are_the_means_of_their_trials(tmp_path):
    table = tmp_path / "trials.csv"
    table.write_text('name,speed\na.csv,slow\nb,fast\n"c","slow"\n', encoding="utf-8")
    recordings = {"a": _table(1.0), "b": _table(4.0), "c": _table(2.0), "d": _table(8.0)}
    assert groups(recordings, f"{table}:speed") == {"a": "slow", "b": "fast", "c": "slow"}
    result = by_group(recordings, f"{table}:speed")
    assert result["slow"]["trials"] == 2 and result["fast"]["trials"] == 1
    assert result["slow"]["mean"]["wiener"]["inclination_rmse_deg"] == pytest.approx(1.5)
    assert result["slow"]["mean"]["wiener"]["heading_rmse_deg"] == pytest.approx(3.0)


def test_a_table_without_the_column_is_refused_by_name(tmp_path):
    table = tmp_path / "trials.csv"
    table.write_text("name,speed\na,slow\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"needs the columns 'name' and 'group'; it has name, speed"):
        groups(["a"], f"{table}:group")
    with pytest.raises(ValueError, match=r"--by takes 'broad' or TABLE.csv:COLUMN"):
        groups(["a"], "speed")
