"""Axis maps (--gyr-axes, --acc-axes, --mag-axes) and the check that a recording's
accelerometer and magnetometer turn as its gyro says."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings import axes
from attitude_fmu.systems.recordings.axes import MAPS, axes_text, parse_axes
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import IMU_COLUMNS, MAG_COLUMNS
from attitude_fmu.systems.simulation.motion import PROFILES, HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0


def test_maps_read_and_write_as_signed_permutations():
    """Every map and its negative reads back from its text; y,x,-z takes x from the file's
    y, y from its x and z from its −z; text that is not a signed permutation is refused."""
    for matrix in MAPS:
        for m in (matrix, -matrix):
            assert np.array_equal(parse_axes(axes_text(m)), m)
    assert len({axes_text(m) for m in MAPS} | {axes_text(-m) for m in MAPS}) == 48
    assert np.array_equal(np.array([[1.0, 2.0, 3.0]]) @ parse_axes("y, x, -z").T, [[2.0, 1.0, -3.0]])
    assert np.array_equal(parse_axes("+X,y,z"), np.eye(3))
    for bad in ("x,x,z", "x,y", "--x,y,z", "a,b,c", "x,y,z,x", ""):
        with pytest.raises(ValueError, match="names x, y and z once each"):
            parse_axes(bad)


@pytest.fixture(scope="module")
def human():
    """300 s of human motion at 100 Hz (gyro noise 0.1 °/s/√Hz and an offset, hard iron):
    (t, gyr, acc, mag) in the recording's frame."""
    motion = HumanMotion(delta_v=0.25, omega_c=5.0, rot_rms=0.5).generate(300.0, FS, seed=5)
    imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.02, -0.01, 0.005), mag_noise=0.2,
                   mag_offset=(15.0, -10.0, 5.0))
    gyr, acc = imu.apply(motion, seed=6)
    return np.arange(1, len(gyr) + 1) / FS, gyr, acc, imu.apply_mag(motion, seed=6)


def _write(path, t, gyr, acc, mag):
    names = ("t", *IMU_COLUMNS, *MAG_COLUMNS)
    np.savetxt(path, np.column_stack([t, gyr, acc, mag]), delimiter=",", header=",".join(names), comments="",
               fmt="%.17g")


def _estimate(tmp_path, capsys, name, *flags):
    out = tmp_path / f"{name}.out.csv"
    assert main(["estimate", str(tmp_path / f"{name}.csv"), "--out", str(out), *flags]) == 0
    return np.loadtxt(out, delimiter=",", skiprows=1), capsys.readouterr().err


def test_sensors_on_other_axes_are_named_and_their_maps_give_the_estimate_back(tmp_path, human, capsys):
    """An accelerometer on other axes than the gyro (y,-x,z read as x,y,z) and an MPU-9250's
    magnetometer (x and y swapped, z reversed) are each noted with the flag that maps them
    back, and with those flags the estimate is the recording's in its own axes to 1e-12;
    a gyro turning the other way is noted with --gyr-axes=-x,-y,-z. The recording in its
    own axes gets no such note."""
    t, gyr, acc, mag = human
    _write(tmp_path / "true.csv", t, gyr, acc, mag)
    truth, err = _estimate(tmp_path, capsys, "true")
    assert "does not turn" not in err, err
    acc_file, mag_file = acc @ parse_axes("y,-x,z"), mag @ parse_axes("y,x,-z")  # file = P⁻¹·true: P maps back
    _write(tmp_path / "swapped.csv", t, gyr, acc_file, mag_file)
    _, err = _estimate(tmp_path, capsys, "swapped")
    assert "the accelerometer does not turn as the gyro says" in err and "with --acc-axes=y,-x,z it is" in err, err
    assert "the magnetometer does not turn as the gyro says" in err and "with --mag-axes=y,x,-z it is" in err, err
    assert "--acc-axes=-y,x,-z, the same with the sign of the accelerometer reversed, fits as well" in err
    named = [flag for note in err.splitlines() if " it is " in note
             for flag in note.split("with ")[1].split(" it is")[0].split()]
    assert named == ["--acc-axes=y,-x,z", "--mag-axes=y,x,-z"], named  # passed below as the notes write them
    mapped, err = _estimate(tmp_path, capsys, "swapped", *named)
    assert "does not turn" not in err, err
    assert np.abs(mapped - truth).max() < 1e-12
    _write(tmp_path / "reversed.csv", t, -gyr, acc, mag)
    _, err = _estimate(tmp_path, capsys, "reversed")
    assert "with --gyr-axes=-x,-y,-z it is" in err, err
    assert np.abs(_estimate(tmp_path, capsys, "reversed", "--gyr-axes=-x,-y,-z")[0] - truth).max() < 1e-12


def test_motions_in_their_own_axes_are_not_noted(tmp_path):
    """Every closed-form motion profile at its defaults (single-axis turns, a level lever
    arm, no turn at all) read from a .mat in its own axes: no axis note, whatever little
    the motion tells the maps apart. (human at its defaults, Rizun's vigorous 1 m/s/√Hz,
    is beyond a plausible accelerometer; the human case is the test above.)"""
    from scipy.io import savemat

    for name, prof in PROFILES.items():
        if name == "human":
            continue
        motion = prof.motion().generate(120.0, FS, seed=1)
        imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.01, -0.01, 0.005))
        gyr, acc = imu.apply(motion, seed=2)
        savemat(tmp_path / "m.mat", {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": imu.apply_mag(motion, seed=2),
                                     "sampling_rate": FS})
        notes = read_recording(tmp_path / "m.mat").notes
        assert not [n for n in notes if "does not turn" in n], (name, notes)


def test_a_bad_axis_map_is_refused_before_any_work(tmp_path, human, capsys):
    t, gyr, acc, mag = human
    _write(tmp_path / "in.csv", t[:100], gyr[:100], acc[:100], mag[:100])
    with pytest.raises(SystemExit):
        main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "o.csv"), "--acc-axes", "x,x,z"])
    assert "names x, y and z once each" in capsys.readouterr().err
    assert not (tmp_path / "o.csv").exists()


def test_a_join_between_stretches_is_left_out():
    """A pair of windows across a join (mismatches' joins) is left out: a vector that stays put in
    each of two stretches but jumps between them (as the gyro integrated through a join cannot
    follow) mismatches nothing with the join given, and without it the jump's square, 2g², is
    shared among the pairs."""
    fs, g = 10.0, 9.81
    window = round(axes.WINDOW_S * fs)
    n, half = 40 * window, 20 * window
    frames = {False: Rotation.identity(n)}
    vectors = np.where(np.arange(n)[:, None] < half, [0.0, 0.0, g], [g, 0.0, 0.0])
    joined = axes.mismatches(frames, vectors, fs, maps=MAPS[:1], min_turn=0.0, joins=[20])
    plain = axes.mismatches(frames, vectors, fs, maps=MAPS[:1], min_turn=0.0)
    assert joined[(0, False)] == 0.0
    assert plain[(0, False)] == pytest.approx(2 * g * g / 39, rel=1e-12)


def test_a_long_recording_is_checked_on_stretches_spread_over_it():
    """Beyond CHECK_S (300 s) the check runs on PARTS stretches of whole windows, CHECK_S in all,
    one at the start of each of as many equal parts, joined at the windows that begin them; on
    900 s of human motion an accelerometer on other axes is still named, and the recording in its
    own axes gets no note."""
    n = round(900.0 * FS)
    rows, joins = axes._checked_rows(n, FS)
    assert len(rows) == round(axes.CHECK_S * FS) and joins == [50, 100]  # 2-s windows of every 2nd sample
    starts = rows[np.flatnonzero(np.diff(rows, prepend=-2) != 1)]
    assert list(starts) == [0, n // 3, 2 * n // 3]
    assert axes._checked_rows(round(axes.CHECK_S * FS), FS)[1] == []  # up to CHECK_S: every row
    motion = HumanMotion(delta_v=0.25, omega_c=5.0, rot_rms=0.5).generate(900.0, FS, seed=7)
    imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.02, -0.01, 0.005))
    gyr, acc = imu.apply(motion, seed=8)
    assert axes.axes_notes("long", gyr, acc, None, FS) == []
    notes = axes.axes_notes("long", gyr, acc @ parse_axes("y,-x,z"), None, FS)
    assert len(notes) == 1 and "with --acc-axes=y,-x,z it is" in notes[0], notes
