"""`attitude evaluate`: recordings with an optical reference (BROAD), errors as the
dataset defines them, for a project method and, on the same samples, vqf online and
offline and ahrs' Madgwick."""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from attitude_fmu.blocks.errors import quaternion_errors
from attitude_fmu.blocks.pipeline.batch import check_options, estimate
from attitude_fmu.blocks.stages.delays import best_shift
from attitude_fmu.blocks.stages.timing import carry_forward_rows, interval_ends, interval_means
from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.evaluation.alignment import align as align_reference
from attitude_fmu.systems.evaluation.alignment import heading_offset, reference_rates, without_heading_offset
from attitude_fmu.systems.evaluation.compare import peer_quaternions
from attitude_fmu.systems.evaluation.groups import groups
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import Recording, print_notes

METRICS = ("total_rmse_deg", "heading_rmse_deg", "inclination_rmse_deg")
LATENCY_SEARCH_S = 0.1  # imu_latency looks this far either way
LATENCY_SAMPLES = 200_000  # at most this many gyro samples, evenly spread, enter imu_latency's fit
REFERENCE_ORDERS = {  # a reference stored otherwise, as its columns w,x,y,z read it, turned back
    "stored x,y,z,w (scalar last)": lambda q: np.roll(q, 1, axis=1),
    "the inverse, earth → sensor": lambda q: q * [1.0, -1.0, -1.0, -1.0],
    "stored x,y,z,w and the inverse": lambda q: np.roll(q, 1, axis=1) * [1.0, -1.0, -1.0, -1.0],
}
REFERENCE_RATIO = 4.0  # how much better another order must fit the estimate to be noted
REFERENCE_NOTE_DEG = 5.0  # nor is anything said below this inclination RMSE (deg) as the reference is read
MAG_USED_NOTE = 0.5  # a recording whose heading used fewer of the movement's field samples than this is noted
REFERENCE_NORTH = ("other", "magnetic")  # the reference's north: another (its offset removed), or magnetic


def magnetic_north(reference_north: str) -> bool:
    """Whether a reference has the estimate's north: "magnetic" (BROAD's references) yes, "other" no."""
    if reference_north not in REFERENCE_NORTH:
        raise ValueError(f"reference north must be one of {', '.join(REFERENCE_NORTH)}, got {reference_north!r}")
    return reference_north == "magnetic"


def errors_on_movement(quat, rec: Recording, magnetic_north: bool = True) -> dict:
    """RMSE (deg) of total, heading and inclination error over Recording.evaluated (the
    movement phase where the reference is finite; BROAD's definitions, see
    blocks.errors.quaternion_errors). magnetic_north False: the reference's north is not the
    estimate's, so the constant heading offset between them (their turn about the vertical,
    circular mean over those samples: systems.evaluation.alignment.heading_offset) is removed first."""
    ok = rec.evaluated() & np.isfinite(quat).all(axis=1)
    ref = rec.quat_ref[ok]
    if not magnetic_north:
        ref = without_heading_offset(ref, heading_offset(quat[ok], ref))
    errors = quaternion_errors(quat[ok], ref)
    return {name: math.degrees(float(np.sqrt(np.mean(e**2)))) for name, e in zip(METRICS, errors)}


def reference_order_note(rec: Recording, quat) -> str | None:
    """A note where the reference read in another order (REFERENCE_ORDERS) fits the
    estimate quat (N×4) REFERENCE_RATIO times better in inclination RMSE over
    Recording.evaluated than as read, and that is REFERENCE_NOTE_DEG or more."""
    ok = rec.evaluated()
    rmse = lambda ref: math.degrees(float(np.sqrt(np.mean(quaternion_errors(quat[ok], ref)[2] ** 2))))
    given = rmse(rec.quat_ref[ok])
    if given < REFERENCE_NOTE_DEG:
        return None
    fits = {label: rmse(turn(rec.quat_ref[ok])) for label, turn in REFERENCE_ORDERS.items()}
    label = min(fits, key=fits.get)
    if REFERENCE_RATIO * fits[label] >= given:
        return None
    return (f"{rec.name}: the reference fits the estimate far better read as {label} (inclination RMSE "
            f"{fits[label]:.2f}° against {given:.2f}° as read, w,x,y,z sensor → earth): is it stored so? Give it "
            "as w,x,y,z sensor → earth (a CSV's columns can be named so with --column ref_q_w=NAME ...)")


def imu_latency(rec: Recording) -> float | None:
    """The IMU's latency behind its reference (s, in blocks.stages.timing's convention): the
    shift of the reference's mean rate over each sample time that best matches the gyro,
    least squares over the movement phase (at most LATENCY_SAMPLES of it) within
    ±LATENCY_SEARCH_S (blocks.stages.delays.best_shift).
    None where the reference gives fewer than a second of rates or the best shift lies at
    the search's edge."""
    rate = reference_rates(rec.quat_ref, rec.fs)  # rate[k]: the reference's mean rate over (t_k−1, t_k]
    k = np.flatnonzero(np.isfinite(rate).all(axis=1) & (True if rec.movement is None else rec.movement))
    if len(k) < rec.fs:
        return None
    k = k[::-(-len(k) // LATENCY_SAMPLES)]
    gyr, index = rec.gyr[k], np.arange(len(rate))

    def mismatch(lag):  # gyro sample k against the reference's rate at k − lag (samples)
        shifted = np.column_stack([np.interp(k - lag, index, rate[:, i]) for i in range(3)])
        return float(np.nanmean(np.sum((gyr - shifted) ** 2, axis=1)))

    lag = best_shift(mismatch, LATENCY_SEARCH_S * rec.fs)
    return None if lag is None else lag / rec.fs


def method_label(method: str, offline: bool) -> str:
    """The method's key in a recording's table."""
    return f"{method}_offline" if offline else method


def evaluate_recording(rec: Recording, method: str = "wiener", params=None, offline: bool = False,
                       gyro_offset: bool = True, use_mag: bool = True, latency: float = 0.0,
                       peers: bool = True, threads: int | None = None, align: bool = False,
                       magnetic: bool = False, alignment: dict | None = None, chosen: dict | None = None,
                       mag_used: dict | None = None) -> dict:
    """{method label: {metric: value}} for one recording; with a magnetometer (and use_mag)
    the method's heading comes from it, and vqf's 9D estimate is added as "vqf_9d". A
    reference that fits far better in another order is noted in rec.notes
    (reference_order_note).
    latency (s): every estimate, the peers' too, is carried forward over the IMU's delay
    (blocks.stages.timing; the peers' with the raw gyro). peers=False: the method's alone.
    threads: the estimate's (blocks.pipeline.batch.estimate; None: its own choice).
    align: the reference is first brought into the IMU's frames (systems.evaluation.alignment:
    lag, mounting, up axis, heading offset), what was found put into the dict alignment when
    given (Alignment.to_json). magnetic: the reference's north is magnetic north, the
    estimate's; else (the default) each estimate's constant heading offset from the reference is
    removed before its heading error (errors_on_movement). chosen: a dict that receives the
    parameters the estimate chose from the recording (AttitudeEstimate.chosen), when given;
    mag_used: a dict that receives {"fraction": the share of the movement's field samples the
    heading used (the rest the disturbance guard refused)}, when given and heading came from the
    magnetometer; below MAG_USED_NOTE a note in rec.notes says so (mag_used_note)."""
    rec.evaluated()  # refuses a recording without a usable reference before any work
    label = method_label(method, offline)
    mag = rec.mag if use_mag else None
    est = estimate(rec.gyr, rec.acc, rec.fs, method, params, offline=offline, gyro_offset=gyro_offset, mag=mag,
                   latency=latency, threads=threads)
    if align:
        found, quat_ref = align_reference(rec, est.quat)
        rec = replace(rec, quat_ref=quat_ref)
        if alignment is not None:
            alignment.update(found.to_json())
    gyr, acc = np.ascontiguousarray(rec.gyr), np.ascontiguousarray(rec.acc)

    def peer(quat):
        quat = np.array(quat, dtype=float)
        if latency:
            carry_forward_rows(quat, np.zeros_like(gyr), gyr, latency)
        return errors_on_movement(quat, rec, magnetic)

    note = None if align else reference_order_note(rec, est.quat)
    if note:
        rec.notes.append(note)
    if est.chosen is not None and chosen is not None:
        chosen.update(est.chosen)
    if est.mag_accepted is not None:
        sampled = rec.evaluated() & np.isfinite(mag).all(axis=1)
        fraction = float(est.mag_accepted[sampled].mean()) if sampled.any() else math.nan
        if mag_used is not None:
            mag_used["fraction"] = fraction
        note = mag_used_note(rec.name, fraction, params)
        if note:
            rec.notes.append(note)
    if not peers:
        return {label: errors_on_movement(est.quat, rec, magnetic)}
    import vqf as vqf_module  # peers: the test extra (or [peers])

    table = {
        label: errors_on_movement(est.quat, rec, magnetic),
        "vqf": peer(peer_quaternions("vqf", gyr, acc, rec.fs)),
        "vqf_offline": peer(peer_quaternions("vqf_offline", gyr, acc, rec.fs)),
        "madgwick": peer(peer_quaternions("madgwick", gyr, acc, rec.fs)),
    }
    if mag is not None:  # vqf's "no sample" is a zero row, where ours is NaN
        mag = np.ascontiguousarray(np.where(np.isnan(mag).any(axis=1, keepdims=True), 0.0, mag))
        table["vqf_9d"] = peer(vqf_module.VQF(1.0 / rec.fs).updateBatch(gyr, acc, mag)["quat9D"])
    return table


def mag_used_note(name: str, fraction: float, params=None) -> str | None:
    """A note where the heading used fewer than MAG_USED_NOTE of the movement's field samples
    (fraction; params: the evaluation's, whose mag_norm_tol and mag_dip_tol it names)."""
    if not fraction < MAG_USED_NOTE:
        return None
    from attitude_fmu.blocks.stages import heading

    given = heading.resolve({k: v for k, v in (params or {}).items() if k in ("mag_norm_tol", "mag_dip_tol")})
    return (f"{name}: the heading used the magnetometer for {100 * fraction:.0f} % of the movement's field samples; "
            f"the disturbance guard refused the rest (norm more than {100 * given['mag_norm_tol']:g} % or dip more "
            f"than {math.degrees(given['mag_dip_tol']):g}° off the reference): a disturbed place, or a field the "
            "magnetometer's calibration leaves off? --param mag_norm_tol=F --param mag_dip_tol=RAD widen the guard")


@dataclass(frozen=True)
class Setup:
    """How each recording of an evaluation is read, prepared and estimated (the arguments of
    evaluate, which documents them); a sweep varies params."""

    method: str = "wiener"
    params: dict | None = None
    offline: bool = False
    gyro_offset: bool = True
    use_mag: bool = True
    start_in_movement: float | None = None
    read_options: dict | None = None
    latency: float = 0.0
    gyr_samples: str = "mean"
    acc_samples: str = "point"
    threads: int | None = None  # the estimate's (job_threads)
    align: bool = False
    reference_north: str = "other"

    def check(self) -> None:
        """Refuse the options before any file is read (blocks.pipeline.batch.check_options)."""
        check_options(self.method, self.params, self.offline, self.gyro_offset, self.use_mag, self.latency,
                      self.gyr_samples, self.acc_samples)
        magnetic_north(self.reference_north)


def read_prepared(path, setup: Setup) -> Recording:
    """The recording at path as setup evaluates it: read, its samples turned to the
    project's convention, cut into its movement."""
    rec = read_recording(path, **(setup.read_options or {}))
    if setup.gyr_samples == "point":
        rec = replace(rec, gyr=interval_means(rec.gyr))
    if setup.acc_samples == "mean":
        rec = replace(rec, acc=interval_ends(rec.gyr, rec.acc, 1.0 / rec.fs))
    if setup.start_in_movement is not None:
        rec = rec.into_movement(setup.start_in_movement)
    return rec


def evaluate_file(path, setup: Setup, peers: bool = True) -> dict:
    """One recording's job: {"table": {label: metrics}, "imu_latency_s": seconds or None,
    "notes": [how it was read]}, and with setup.align "alignment" (Alignment.to_json; the
    IMU's latency is then its lag_s, imu_latency_s None); peers=False: the method's errors
    alone ("table" holds the method's label only, imu_latency_s None), as a sweep needs them."""
    rec = read_prepared(path, setup)
    alignment = {} if setup.align else None
    chosen, mag_used = {}, {}
    table = evaluate_recording(rec, setup.method, setup.params, setup.offline, setup.gyro_offset, setup.use_mag,
                               setup.latency, peers, setup.threads, setup.align,
                               magnetic_north(setup.reference_north), alignment, chosen, mag_used)
    notes = rec.notes + ([f"{rec.name}: no movement flag; errors over every sample with a reference"]
                         if rec.movement is None else [])
    result = {"table": table, "imu_latency_s": imu_latency(rec) if peers and not setup.align else None,
              "notes": notes, "chosen": chosen, "mag_used": mag_used.get("fraction")}
    return result if alignment is None else {**result, "alignment": alignment}


def job_threads(jobs: Jobs) -> int | None:
    """The threads of each job's estimate: 1 where the jobs run on Dask workers (a process on
    every core already), None (the estimate's own choice) where they run in this process."""
    return 1 if jobs.scheduler is not None or jobs.workers > 1 else None


def recording_names(paths) -> list[str]:
    """Each file's key in a result: its stem, or its path where stems repeat (files of one
    name from several folders)."""
    stems = [Path(path).stem for path in paths]
    return stems if len(set(stems)) == len(stems) else [str(path) for path in paths]


def mean_over(tables) -> dict:
    """{label: {metric: mean}} over recordings' tables, for the labels every table has
    (vqf_9d needs every file's magnetometer)."""
    tables = list(tables)
    if not tables:
        return {}
    labels = set.intersection(*(set(t) for t in tables))
    return {label: {m: float(np.mean([t[label][m] for t in tables])) for m in METRICS}
            for label in tables[0] if label in labels}


def by_group(recordings: dict, by: str) -> dict:
    """{group: {"trials": n, "mean": {label: {metric: mean}}}} over the recordings' tables (name →
    table) of each group (systems.evaluation.groups.groups: by "broad" or "TABLE.csv:COLUMN")."""
    of = groups(recordings, by)
    return {group: {"trials": sum(g == group for g in of.values()),
                    "mean": mean_over(recordings[name] for name, g in of.items() if g == group)}
            for group in sorted(set(of.values()))}


def evaluate(paths, method: str = "wiener", params=None, offline: bool = False, gyro_offset: bool = True,
             use_mag: bool = True, progress: bool = True, start_in_movement: float | None = None,
             read_options=None, latency: float = 0.0, gyr_samples: str = "mean", acc_samples: str = "point",
             jobs: Jobs | None = None, align: bool = False, reference_north: str = "other",
             by: str | None = None) -> dict:
    """{"recordings": {name: {label: metrics}}, "mean": {label: metrics}, "imu_latency_s":
    {name: seconds or None}} over the files (imu_latency: the IMU's delay behind the
    reference, measured, whatever latency (s) the estimates were carried forward by), and
    "failed": {name: message} for files that could not be evaluated, when there are any (the
    others complete; jobs reports them);
    gyr_samples "point": every recording's gyro is turned into interval means first
    (blocks.stages.timing.interval_means), for the peers and the latency measured as well;
    acc_samples "mean": every accelerometer mean is turned into the sensor frame at its
    sample's time first (blocks.stages.timing.interval_ends), for the peers as well;
    start_in_movement (s): cut each recording to begin that long into its movement phase;
    read_options: keyword arguments of read_recording (units, fs, max_gap). A recording's
    name is recording_names'. Each file is a job of jobs (systems.cluster.jobs.Jobs; default:
    this process, a bar when progress); results are those of the serial run, in the files'
    order. progress also prints how each file was read where it matters (time stamps, no
    movement flag).
    align: each reference is first brought into its IMU's frames (lag, mounting, up, heading
    offset: systems.evaluation.alignment), what was found under "alignment": {name: {lag_s,
    mounting_quat, up_axis, heading_offset_deg, misfit}}. reference_north: "other" (each
    estimate's constant heading offset from the reference is removed before its heading error)
    or "magnetic" (the reference's north is magnetic north, as BROAD's: kept). by: the means over each group of recordings too, under "by_group"
    (by_group). "chosen": {name: {parameter: value}} holds what each estimate chose from its
    recording (blocks.stages.scale_error, blocks.stages.heading_choice), where it chose.
    "mag_used": {name: fraction} holds the share of each recording's field samples over the
    movement that its heading used (the disturbance guard refused the rest), where the heading
    came from the magnetometer; a recording under MAG_USED_NOTE is noted."""
    jobs = jobs or Jobs(bar=progress)
    setup = Setup(method, params, offline, gyro_offset, use_mag, start_in_movement, read_options, latency,
                  gyr_samples, acc_samples, job_threads(jobs), align, reference_north)
    setup.check()
    if by:
        groups([], by)  # a table that cannot group is refused before any recording is read
    names = recording_names(paths)
    results = jobs.map(evaluate_file, [(str(Path(path).absolute()), setup) for path in paths], list(map(str, paths)),
                       "recordings")
    done = {name: result for name, result in zip(names, results) if not isinstance(result, Failure)}
    if progress:
        print_notes(note for result in done.values() for note in result["notes"])
    lags = {name: result["imu_latency_s"] for name, result in done.items()}
    found = [lag for lag in lags.values() if lag is not None]
    if progress and found:
        print(f"attitude: note: the IMU lags the reference by {1e3 * min(found):.2f} to {1e3 * max(found):.2f} ms "
              f"(gyro against the reference's rate); --latency S carries every estimate forward by S seconds "
              f"(now {latency:g})", file=sys.stderr)
    recordings = {name: result["table"] for name, result in done.items()}
    out = {"recordings": recordings, "mean": mean_over(recordings.values()), "imu_latency_s": lags}
    if align:
        out["alignment"] = {name: result["alignment"] for name, result in done.items()}
    chosen = {name: result["chosen"] for name, result in done.items() if result.get("chosen")}
    if chosen:
        out["chosen"] = chosen
    mag_used = {name: result["mag_used"] for name, result in done.items() if result.get("mag_used") is not None}
    if mag_used:
        out["mag_used"] = mag_used
    if by:
        out["by_group"] = by_group(recordings, by)
    failed = {name: result.message for name, result in zip(names, results) if isinstance(result, Failure)}
    if failed:
        out["failed"] = failed
    return out
