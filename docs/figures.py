"""Every table and figure of the docs' results pages, from the project's own commands.

    python docs/figures.py [--broad DIR] [--only NAME ...]

runs `attitude table1 --json`, `attitude evaluate --json` (online and --offline) on the BROAD
recordings and on recordings `attitude simulate` makes, the scenario suite (systems.evaluation.scenarios),
`attitude compare --json`, `attitude verify --json`, `attitude bench --json` (also
`--fmu`, `--io` and `--workers 2`),
`attitude bode` and `attitude plot`, writes what each printed to docs/generated/NAME.json, and
from those files the Markdown tables (NAME.md, included by the pages) and the figures
(NAME.png). Running it again refreshes every number and picture in docs/results/. It takes
about half an hour on 2 cores (Table 1's 20 000 s per cell and verify dominate).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parent
OUT = DOCS / "generated"
BROAD = Path(os.environ.get("BROAD_DIR", DOCS.parent.parent / "shared" / "broad"))
METRICS = ("inclination_rmse_deg", "heading_rmse_deg")


def attitude(*args: str) -> str:
    """What `attitude ARGS` prints on standard output (its notes go to the terminal)."""
    return subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", *args], check=True,
                          stdout=subprocess.PIPE, text=True).stdout


def run_json(name: str, *args: str) -> dict:
    data = json.loads(attitude(*args, "--json"))
    (OUT / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")
    return data


def load(name: str):
    return json.loads((OUT / f"{name}.json").read_text())


def write_md(name: str, lines) -> None:
    (OUT / f"{name}.md").write_text("\n".join(lines) + "\n")


def save_png(fig, name: str) -> None:
    """fig laid out and written to docs/generated/NAME.png, then closed."""
    fig.tight_layout()
    fig.savefig(OUT / f"{name}.png", dpi=110)
    pyplot().close(fig)


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def table1(refresh: bool) -> None:
    rows = run_json("table1", "table1") if refresh else load("table1")
    heads = [f"a = {c['a']:g}" for c in rows[0]["cells"]]
    lines = ["| δn °/s/√Hz | δv m/s/√Hz | 1/ω_g s | " + " | ".join(f"{h}: eq. 50 / simulated" for h in heads) + " |",
             "|---:|---:|---:|" + "---:|" * len(heads)]
    worst = 0.0
    for r in rows:
        cells = []
        for c in r["cells"]:
            cells.append(f"{c['analytic_deg']:.3f}° / {c['simulated_deg']:.3f}°")
            worst = max(worst, abs(c["simulated_deg"] / c["analytic_deg"] - 1))
        lines.append(f"| {r['delta_n_deg']:.2f} | {r['delta_v']:.1f} | {r['inv_omega_g_s']:.2f} | " + " | ".join(cells) + " |")
    lines += ["", f"Largest departure of a simulated cell from eq. 50: {100 * worst:.1f} %."]
    write_md("table1", lines)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 5))
    analytic = [c["analytic_deg"] for r in rows for c in r["cells"]]
    simulated = [c["simulated_deg"] for r in rows for c in r["cells"]]
    ax.plot(analytic, simulated, "o", label="simulated cells (20 000 s each)")
    line = [min(analytic) * 0.9, max(analytic) * 1.1]
    ax.plot(line, line, "k-", lw=0.8, label="eq. 50")
    ax.fill_between(line, [0.93 * v for v in line], [1.07 * v for v in line], color="0.9", label="±7 %")
    ax.set_xlabel("eq. 50, degrees RMS")
    ax.set_ylabel("simulated, degrees RMS")
    ax.set_title("Rizun's Table 1: analytic against simulated")
    ax.legend()
    save_png(fig, "table1")


def spectrum(refresh: bool) -> None:
    """The simulated error spectrum of Rizun's stationary filter against eq. 42 (Python API:
    no command prints a spectrum)."""
    if refresh:
        from attitude_fmu.blocks.filters.accuracy import butterworth_error_spectrum
        from attitude_fmu.systems.evaluation.experiments import PAPER_G, simulate_human, simulated_error_spectrum

        delta_n, delta_v = np.radians(0.1), 1.0  # Table 1's first row, the filter of its default wiener
        omega, density = simulated_error_spectrum(simulate_human(delta_n, delta_v, duration=40000.0, seed=5),
                                                  segment_s=1000.0)
        keep = (omega > 0) & (omega < 20.0)
        theory = butterworth_error_spectrum(omega[keep], delta_n, delta_v, PAPER_G)
        (OUT / "spectrum.json").write_text(json.dumps({"delta_n": delta_n, "delta_v": delta_v,
                                                       "omega": omega[keep].tolist(),
                                                       "simulated": density[keep].tolist(),
                                                       "eq42": np.asarray(theory).tolist()}) + "\n")
    data = load("spectrum")
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.loglog(data["omega"], data["simulated"], lw=0.8, label="simulated: 40 000 s of human motion, Welch")
    ax.loglog(data["omega"], data["eq42"], "k--", label="eq. 42")
    ax.set_xlabel("ω, rad/s")
    ax.set_ylabel("S(ω) of a horizontal component of ĝ, (m/s²)²/(rad/s)")
    ax.set_title("Error spectrum of Rizun's filter (δn = 0.1 °/s/√Hz, δv = 1 m/s/√Hz)")
    ax.legend()
    save_png(fig, "spectrum")


def broad(refresh: bool) -> None:
    files = sorted(str(p) for p in BROAD.glob("*.mat"))
    if refresh:
        if not files:
            raise SystemExit(f"no BROAD recordings in {BROAD} (set BROAD_DIR)")
        run_json("broad", "evaluate", "--reference-north", "magnetic", *files)
        run_json("broad_offline", "evaluate", "--reference-north", "magnetic", "--offline", *files)
        run_json("broad_latency", "evaluate", "--reference-north", "magnetic", "--latency", "0.0021", *files)
        attitude("plot", str(BROAD / "21_undisturbed_fast_combined.mat"), "--reference-north", "magnetic", "--out",
                 str(OUT / "plot_21.png"))
    online, offline = load("broad"), load("broad_offline")
    for name, data in (("broad", online), ("broad_offline", offline)):
        labels = list(data["mean"])
        lines = ["| recording | " + " | ".join(labels) + " | IMU lag, ms |", "|---|" + "---:|" * (len(labels) + 1)]
        for rec, table in [*data["recordings"].items(), ("**mean**", data["mean"])]:
            lag = data["imu_latency_s"].get(rec)
            cells = [f"{table[l]['inclination_rmse_deg']:.2f} / {table[l]['heading_rmse_deg']:.2f}" for l in labels]
            lines.append(f"| {rec} | " + " | ".join(cells) + f" | {'' if lag is None else format(1e3 * lag, '.2f')} |")
        write_md(name, lines)
    latency = load("broad_latency")["mean"]
    write_md("broad_latency", ["| `--latency 0.0021` | " + " | ".join(latency) + " |", "|---|" + "---:|" * len(latency),
                               "| inclination | " + " | ".join(f"{v['inclination_rmse_deg']:.3f}°" for v in latency.values()) + " |",
                               "| heading | " + " | ".join(f"{v['heading_rmse_deg']:.2f}°" for v in latency.values()) + " |"])
    plt = pyplot()
    names = [r.split("_")[0] for r in online["recordings"]]
    methods = [("wiener", online), ("vqf", online), ("vqf_9d", online), ("wiener_offline", offline),
               ("vqf_offline", offline)]
    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    width = 0.8 / len(methods)
    for ax, metric, title in zip(axes, METRICS, ("inclination", "heading")):
        for i, (label, data) in enumerate(methods):
            values = [data["recordings"][r][label][metric] for r in data["recordings"]]
            ax.bar(np.arange(len(names)) + (i - len(methods) / 2 + 0.5) * width, values, width, label=label)
        ax.set_ylabel(f"{title} RMSE, degrees")
        ax.set_yscale("log")
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(ncol=len(methods), fontsize=8)
    axes[1].set_xticks(np.arange(len(names)), names)
    axes[1].set_xlabel("BROAD recording")
    axes[0].set_title("BROAD: error of each method per recording (defaults; vqf_9d and wiener use the magnetometer)")
    save_png(fig, "broad")


SIMULATED_RATES = (40, 125, 1000)  # Hz: the rates of the simulated recordings
SIMULATED_VIGOUR = (0.02, 0.3)  # m/s/√Hz: the human motion's slosh (delta_v) at 125 Hz; the default is 0.1


def _simulated_runs(specs) -> dict:
    """`attitude simulate` for each (name, its flags), scored by `attitude evaluate` online and
    --offline: {"online": …, "offline": …} as evaluate printed them."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        files = []
        for name, flags in specs:
            files.append(str(Path(folder) / f"{name}.csv"))
            attitude("simulate", *flags, "--seed", "1", "--out", files[-1])
        return {"online": json.loads(attitude("evaluate", "--reference-north", "magnetic", "--json", *files)),
                "offline": json.loads(attitude("evaluate", "--reference-north", "magnetic", "--offline", "--json",
                                               *files))}


def _simulated_table(data) -> list[str]:
    online, offline = data["online"], data["offline"]
    labels = [("wiener", online), ("vqf", online), ("vqf_9d", online), ("wiener_offline", offline),
              ("vqf_offline", offline)]
    lines = ["| recording | scale_error chosen | " + " | ".join(label for label, _ in labels) + " |",
             "|---|---:|" + "---:|" * len(labels)]
    for rec in online["recordings"]:
        chosen = online.get("chosen", {}).get(rec, {}).get("scale_error")
        cells = [f"{d['recordings'][rec][label]['inclination_rmse_deg']:.3f} / "
                 f"{d['recordings'][rec][label]['heading_rmse_deg']:.2f}" for label, d in labels]
        lines.append(f"| {rec} | {'' if chosen is None else format(chosen, 'g')} | " + " | ".join(cells) + " |")
    return lines


def simulated(refresh: bool) -> None:
    """`attitude simulate` (300 s of motion, seed 1) scored by `attitude evaluate` online and --offline:
    each sensor at each rate (simulated.json, {"online": …, "offline": …} as evaluate printed them), and
    each sensor at 125 Hz in gentler and more vigorous motion (simulated_motion.json, the same)."""
    from attitude_fmu.systems.simulation.recording import SENSORS

    if refresh:
        rates = _simulated_runs((f"{sensor}_{fs}Hz", ("--sensor", sensor, "--fs", str(fs)))
                                for sensor in SENSORS for fs in SIMULATED_RATES)
        (OUT / "simulated.json").write_text(json.dumps(rates, indent=1) + "\n")
        motion = _simulated_runs((f"{sensor}_delta_v_{dv:g}", ("--sensor", sensor, "--fs", "125", "--motion",
                                                                f"delta_v={dv:g}"))
                                 for sensor in SENSORS for dv in SIMULATED_VIGOUR)
        (OUT / "simulated_motion.json").write_text(json.dumps(motion, indent=1) + "\n")
    write_md("simulated", _simulated_table(load("simulated")))
    write_md("simulated_motion", _simulated_table(load("simulated_motion")))


def scenarios(refresh: bool) -> None:
    """The scenario suite (systems.evaluation.scenarios): ours against vqf in each column, online and
    offline, 6D and 9D (scenarios.json, {scenario: {column: {"ours", "vqf"}}}); a cell where vqf is
    ahead is marked."""
    if refresh:
        from attitude_fmu.systems.evaluation.scenarios import score_all

        (OUT / "scenarios.json").write_text(json.dumps(score_all(), indent=1) + "\n")
    data = load("scenarios")
    columns = list(next(iter(data.values())))
    lines = ["| scenario | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    for name, row in data.items():
        cells = [f"{row[c]['ours']:.2f} / {row[c]['vqf']:.2f}" + (" ✗" if row[c]["ours"] > row[c]["vqf"] else "")
                 for c in columns]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    write_md("scenarios", lines + ["", "RMS error in degrees, ours / vqf's (offline columns: vqf's offline "
                                   "estimate); ✗: vqf ahead."])


def compare(refresh: bool) -> None:
    data = run_json("compare", "compare") if refresh else load("compare")
    methods = list(next(iter(data["profiles"].values())))
    lines = ["| profile | " + " | ".join(methods) + " |", "|---|" + "---:|" * len(methods)]
    for profile, rows in data["profiles"].items():
        lines.append(f"| {profile} | " + " | ".join(f"{rows[m]['rms_deg']:.2f} / {rows[m]['mean_deg']:.2f}"
                                                    for m in methods) + " |")
    write_md("compare", lines)


def verify(refresh: bool) -> None:
    data = run_json("verify", "verify") if refresh else load("verify")
    lines = ["| profile | method | RMS ° | max ° | mean ° | bound ° | on | result |", "|---|---|---:|---:|---:|---:|---|---|"]
    for r in data["rows"]:
        bound = "—" if r["bound_deg"] is None else f"{r['bound_deg']:.3g}"
        result = "report" if r["bound_deg"] is None else "pass" if r["pass"] else "FAIL"
        lines.append(f"| {r['profile']} | {r['method']} | {r['rms_deg']:.3g} | {r['max_deg']:.3g} | "
                     f"{r['mean_deg']:.3g} | {bound} | {r['metric']} | {result} |")
    write_md("verify", lines)


def bench(refresh: bool) -> None:
    data = run_json("bench", "bench") if refresh else load("bench")
    lines = ["| estimator | samples/s | × vqf | × vqf_9d |", "|---|---:|---:|---:|"]
    for name, rate in data["samples_per_s"].items():
        lines.append(f"| {name} | {rate:.3g} | {data['ratio_vs_vqf'][name]:.2f} | {data['ratio_vs_vqf_9d'][name]:.2f} |")
    write_md("bench", lines + ["", f"{data['samples']} samples, best of the runs, all in one process."])


def bench_fmu(refresh: bool) -> None:
    data = run_json("bench_fmu", "bench", "--fmu", "--repeat", "10") if refresh else load("bench_fmu")
    lines = ["| FMU | µs per step under fmpy |", "|---|---:|"]
    lines += [f"| {name} | {us:.2f} |" for name, us in data["us_per_step"].items()]
    lines += ["", "| FMU | µs per step in a C host |", "|---|---:|"]
    lines += [f"| {name} | {us:.3f} |" for name, us in data["c_host_us_per_step"].items()]
    lines += ["", f"Under fmpy the native estimator costs {data['native_ratio_vs_noop']:.2f}× a native no-op FMU of "
              f"its interface (the pythonfmu one {data['ratio_vs_noop']:.2f}× its no-op); in a C host it is "
              f"{data['native_speedup_c_host']:.0f}× faster than the pythonfmu estimator ({data['steps']} steps, "
              "best of interleaved rounds, one process)."]
    write_md("bench_fmu", lines)


def bench_io(refresh: bool) -> None:
    data = run_json("bench_io", "bench", "--io") if refresh else load("bench_io")
    mb = lambda b: f"{b / 1e6:.0f} MB"
    rec = data["recording"]
    lines = ["| way | seconds | × pandas + vqf 9D + pandas | peak memory |", "|---|---:|---:|---:|"]
    for name, seconds in data["seconds"].items():
        memory = data["peak_memory_bytes"].get(name)
        lines.append(f"| {name} | {seconds:.2f} | {data['ratio_vs_peers'][name]:.2f} | {mb(memory) if memory else ''} |")
    lines += ["", f"{data['samples']} samples at {data['fs_hz']:g} Hz with a magnetometer: columns "
              f"{mb(rec['array_bytes'])}, CSV {mb(rec['csv_bytes'])}, Parquet {mb(rec['parquet_bytes'])}; a process "
              f"estimating one second of it peaks at {mb(data['peak_memory_bytes']['one_second'])}."]
    write_md("bench_io", lines)


def bench_workers(refresh: bool) -> None:
    data = (run_json("bench_workers", "bench", "--workers", "2", "--recordings", *map(str, sorted(BROAD.glob("*.mat"))))
            if refresh else load("bench_workers"))
    lines = ["| command | jobs | 1 process, s | 2 workers, s | speed-up | same output |", "|---|---:|---:|---:|---:|---|"]
    for command in ("evaluate", "table1"):
        r = data[command]
        lines.append(f"| attitude {command} | {r['jobs']} | {r['serial_s']:.1f} | {r['distributed_s']:.1f} | "
                     f"{r['ratio']:.2f}× | {'yes' if r['identical'] else 'no'} |")
    write_md("bench_workers", lines + ["", "evaluate on the ten BROAD recordings, table1's twelve cells of 20 000 s; "
                                       "each run a fresh process, start-up included."])


def bode(refresh: bool) -> None:
    if refresh:
        for method in ("tseng", "wiener"):
            attitude("bode", "--method", method, "--out", str(OUT / f"bode_{method}.png"))


FIGURES = {"table1": table1, "spectrum": spectrum, "broad": broad, "simulated": simulated, "scenarios": scenarios,
           "compare": compare,
           "verify": verify,
           "bench": bench, "bench_fmu": bench_fmu, "bench_io": bench_io,
           "bench_workers": bench_workers, "bode": bode}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=list(FIGURES), help="only these (default: all)")
    parser.add_argument("--tables-only", action="store_true",
                        help="redraw tables and figures from the JSON already in docs/generated, running nothing")
    args = parser.parse_args(argv)
    OUT.mkdir(exist_ok=True)
    for name in args.only or FIGURES:
        print(f"figures: {name}", file=sys.stderr, flush=True)
        FIGURES[name](refresh=not args.tables_only)
    return 0


if __name__ == "__main__":
    sys.exit(main())
