"""Jobs: independent jobs run in this process or through dask.distributed, results in the
jobs' order, a failed job reported while the others complete.

A job is a module-level function of this package and its arguments (plain data: paths,
numbers, small dicts), and returns plain data, so what a worker sends back is small.
Recordings and FMUs reach workers as paths, which every worker must see (docs/distributed.md).
A worker lost mid-run has its jobs rerun elsewhere by the scheduler (Dask's own retries,
up to distributed.scheduler.allowed-failures times); a job that raises ValueError,
OSError or RuntimeError (a damaged file, a bad option) is not retried: it is reported and
gives a Failure, and the others complete. Other exceptions are faults of the code and propagate.
"""
from __future__ import annotations

import importlib.metadata
import os
import socket
import struct
import sys
import threading
import uuid
from dataclasses import dataclass

JOB_ERRORS = (ValueError, OSError, RuntimeError)  # a job's own failure, as the CLI reports them
CONNECT_TIMEOUT_S = 10.0  # for --scheduler ADDRESS
GREETING_TIMEOUT_S = 5.0  # a Dask scheduler's first message follows the connection at once
MAX_GREETING_BYTES = 1 << 20  # its length comes first; a handshake takes a few hundred bytes
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")  # a scheduler in another process; inproc:// is one in this process
HANDSHAKE_DEADLINE_S = 20.0  # a scheduler that greets and then says nothing more is given up on after this
SILENCE_S = 60.0  # jobs on a scheduler's workers with none ending this long: the workers are asked whether they answer
PROBE_DEADLINE_S = 30.0  # ... and given up on when one does not answer within this (a stopped worker, a lost machine)
DEFAULT_SCHEDULER_PORT = 8786
WORKER_PLUGIN = "attitude-fmu-worker-exit"


@dataclass(frozen=True)
class Failure:
    """What Jobs.map gives for a job that failed: the message reported."""

    message: str


def default_workers() -> int:
    """The number of cores (os.cpu_count(); 1 where it is not known)."""
    return os.cpu_count() or 1


def attempt(function, args: tuple) -> tuple[str, object]:
    """function(*args) as ("ok", value), or ("error", message) for JOB_ERRORS; runs on a worker."""
    try:
        return "ok", function(*args)
    except JOB_ERRORS as exc:
        return "error", str(exc)


def installed_version() -> str:
    """This package's version where the call runs (a worker's, for Client.run)."""
    return importlib.metadata.version("attitude-fmu")


class Jobs:
    """Runs independent jobs: in this process (workers=1), on a local cluster of that many
    worker processes (one thread each) started on the first map with more than one job, or on
    the Dask cluster whose scheduler is at scheduler (workers then ignored). bar: a progress
    bar over the jobs on standard error when it is a terminal. Use as a context manager; the
    cluster started here is closed on exit. failed: the names of the jobs that failed."""

    def __init__(self, workers: int = 1, scheduler: str | None = None, bar: bool = True):
        if scheduler is None and not (isinstance(workers, int) and workers >= 1):
            raise ValueError(f"the number of workers must be a whole number ≥ 1, got {workers!r}")
        if scheduler is not None:
            scheduler_endpoint(scheduler)  # a scheme this program cannot use: refused before any work
        self.workers, self.scheduler, self.bar = workers, scheduler, bar
        self.failed: list[str] = []
        self.client = None
        self._cluster = None

    def __enter__(self) -> Jobs:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
            self.client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def map(self, function, jobs, names, what: str = "jobs") -> list:
        """[function(*job) for job in jobs] in the jobs' order, a Failure for a job that failed;
        failures are reported on standard error in that order once every job has ended
        (names: one per job, for the report; what: the jobs' plural noun and the bar's label)."""
        jobs, names = list(jobs), list(names)
        if len(names) != len(jobs):
            raise ValueError(f"{len(jobs)} jobs need as many names, got {len(names)}")
        from tqdm import tqdm

        with tqdm(total=len(jobs), desc=what, unit="job", file=sys.stderr, leave=False,
                  disable=not (self.bar and jobs and sys.stderr.isatty())) as bar:
            if self.scheduler is not None or (self.workers > 1 and len(jobs) > 1):
                outcomes = self._on_cluster(function, jobs, what, bar)
            else:
                outcomes = []
                for job in jobs:
                    outcomes.append(attempt(function, job))
                    bar.update()
        self._report(outcomes, names, what)
        return [value if status == "ok" else Failure(value) for status, value in outcomes]

    def _on_cluster(self, function, jobs, what, bar) -> list:
        from distributed import KilledWorker, as_completed

        client = self._start(len(jobs))
        token = uuid.uuid4().hex[:12]
        futures = [client.submit(attempt, function, job, key=f"{what.replace(' ', '-')}-{token}-{i}", pure=False,
                                 priority=len(jobs) - i)  # submitted in order, started in order
                   for i, job in enumerate(jobs)]
        index = {future.key: i for i, future in enumerate(futures)}
        outcomes = [None] * len(jobs)
        for future in as_completed(futures) if self.scheduler is None else self._answered(futures):
            try:
                outcomes[index[future.key]] = future.result()
            except KilledWorker as exc:
                outcomes[index[future.key]] = ("error", (f"every worker that ran it died ({exc}); a job that ends "
                                                         "its process (out of memory, a crash) is not retried further"))
            future.release()
            bar.update()
        return outcomes

    def _answered(self, futures):
        """The futures as they end, on a scheduler whose workers are asked, after SILENCE_S with none ending,
        whether they still answer (RuntimeError where one does not within PROBE_DEADLINE_S): a stopped worker
        holds its jobs until the scheduler's own timeout, minutes later."""
        from distributed import wait

        pending = set(futures)
        while pending:
            try:
                done, pending = wait(pending, timeout=SILENCE_S, return_when="FIRST_COMPLETED")
            except TimeoutError:
                within(PROBE_DEADLINE_S, lambda: self.client.run(os.getpid),
                       f"the workers of {self.scheduler} ran no job to its end for {SILENCE_S:g} s and one did not "
                       f"answer in {PROBE_DEADLINE_S:g} s (stopped, or its machine lost); restart it or run without "
                       "--scheduler")
                continue
            yield from done

    def _start(self, jobs: int):
        """The client, connected on first use: to the scheduler, or to a local cluster of
        min(workers, jobs) worker processes."""
        if self.client is not None:
            return self.client
        import dask
        from distributed import Client, LocalCluster

        from attitude_fmu.systems.cluster.worker_exit import WorkerExit

        if self.scheduler is None:
            # glibc's own trim threshold, not Dask's 64 KiB: the jobs' many large temporaries
            # otherwise cost them about 15 % (evaluate on BROAD)
            environ = {name: value for name, value in dask.config.get("distributed.nanny.pre-spawn-environ").items()
                       if name != "MALLOC_TRIM_THRESHOLD_"}
            with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
                self._cluster = LocalCluster(n_workers=min(self.workers, jobs), threads_per_worker=1,
                                             processes=True, dashboard_address="127.0.0.1:0",  # any free port
                                             scheduler_kwargs={"dashboard": False})
            self.client = Client(self._cluster)
        else:
            check_scheduler(self.scheduler)
            try:
                self.client = within(HANDSHAKE_DEADLINE_S, lambda: Client(self.scheduler, timeout=CONNECT_TIMEOUT_S),
                                     f"the Dask scheduler at {self.scheduler} did not finish its handshake in "
                                     f"{HANDSHAKE_DEADLINE_S:g} s")
            except RuntimeError:
                raise
            except Exception as exc:  # Dask raises many types: the address, the handshake, the security settings
                raise RuntimeError(f"cannot connect to the Dask scheduler at {self.scheduler}: "
                                   f"{str(exc) or type(exc).__name__}") from None
            self._check_workers()
        self.client.register_plugin(WorkerExit(always=self._cluster is not None), name=WORKER_PLUGIN)
        return self.client

    def _check_workers(self) -> None:
        """Refuse a cluster without workers, or whose workers lack this package or run another version."""
        late = f"the Dask scheduler at {self.scheduler} or its workers did not answer in {PROBE_DEADLINE_S:g} s"
        if not within(PROBE_DEADLINE_S, lambda: self.client.scheduler_info(n_workers=-1), late)["workers"]:
            raise RuntimeError(f"the Dask scheduler at {self.scheduler} has no workers; start some with: "
                               f"dask worker {self.scheduler}")
        try:
            versions = within(PROBE_DEADLINE_S, lambda: self.client.run(installed_version), late)
        except RuntimeError:
            raise
        except Exception as exc:  # the worker cannot unpickle a function of this package: it lacks it
            raise RuntimeError(f"the workers of {self.scheduler} cannot run this package's jobs ({exc}); "
                               "install attitude-fmu on every worker (docs/distributed.md)") from None
        ours = installed_version()
        other = {address: version for address, version in versions.items() if version != ours}
        if other:
            raise RuntimeError(f"workers of {self.scheduler} run attitude-fmu "
                               f"{', '.join(f'{v} ({a})' for a, v in sorted(other.items()))}, this client {ours}; "
                               "install the same version on every worker")

    def _report(self, outcomes, names, what) -> None:
        failed = [(i, names[i], message) for i, (status, message) in enumerate(outcomes) if status != "ok"]
        self.failed += [name for _, name, _ in failed]
        if len(outcomes) == 1 and failed:
            print(f"attitude: error: {failed[0][2]}", file=sys.stderr)
            return
        for i, _, message in failed:
            print(f"attitude: [{i + 1}/{len(outcomes)}] error: {message}", file=sys.stderr)
        if failed:
            rest = "the others completed" if len(failed) < len(outcomes) else "none completed"
            print(f"attitude: error: {len(failed)} of {len(outcomes)} {what} failed "
                  f"({', '.join(name for _, name, _ in failed)}); {rest}", file=sys.stderr)


def within(seconds: float, call, late: str):
    """call()'s result, or its exception, if it ends within seconds; else RuntimeError(late). The call is
    left to end in a daemon thread (a Dask client waiting on a socket cannot be interrupted)."""
    result = {}

    def run():
        try:
            result["value"] = call()
        except BaseException as exc:  # handed to the caller's thread
            result["error"] = exc

    thread = threading.Thread(target=run, name="attitude-deadline", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise RuntimeError(late)
    if "error" in result:
        raise result["error"]
    return result["value"]


def scheduler_endpoint(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a --scheduler address (tcp:// when it has no scheme, port
    DEFAULT_SCHEDULER_PORT when it has none); a scheme other than SCHEDULER_SCHEMES, or one
    this installation of Dask lacks, is refused by name (ValueError)."""
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import backends

    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location, DEFAULT_SCHEDULER_PORT)
    except ValueError as exc:
        raise ValueError(f"--scheduler {address}: not an address of a Dask scheduler ({exc}); give "
                         "tcp://HOST:PORT") from None
    if scheme == "inproc":
        raise ValueError(f"--scheduler {address}: inproc:// names a scheduler inside one Python process, which "
                         "a command cannot reach; give its tcp://HOST:PORT address")
    if scheme not in SCHEDULER_SCHEMES or scheme not in backends:
        usable = ", ".join(f"{s}://" for s in SCHEDULER_SCHEMES if s in backends)
        raise ValueError(f"--scheduler {address}: the scheme {scheme}:// is not one to reach a Dask scheduler "
                         f"through; give {usable} HOST:PORT")
    return scheme, host, int(port)


def check_scheduler(address: str) -> None:
    """Refuse (RuntimeError), within CONNECT_TIMEOUT_S + GREETING_TIMEOUT_S, a tcp:// address
    where no Dask scheduler listens: nothing there, or a server that does not greet as a
    scheduler does, with the length of its first message (an HTTP server such as Dask's
    dashboard sends nothing until asked). Other schemes are left to Dask's own timeout."""
    scheme, host, port = scheduler_endpoint(address)
    if scheme != "tcp":
        return
    try:
        connection = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
    except OSError as exc:  # refused, no such host, a timeout
        raise RuntimeError(f"cannot reach the Dask scheduler at {address}: {exc.strerror or exc}") from None
    greeting = b""
    with connection:
        connection.settimeout(GREETING_TIMEOUT_S)
        try:
            while len(greeting) < 8:
                part = connection.recv(8 - len(greeting))
                if not part:
                    break
                greeting += part
        except OSError:  # a timeout: the server waits to be spoken to
            pass
    length = struct.unpack("<Q", greeting)[0] if len(greeting) == 8 else 0
    if not 0 < length <= MAX_GREETING_BYTES:
        said = f"it sent {greeting!r}" if greeting else f"it sent nothing in {GREETING_TIMEOUT_S:g} s"
        raise RuntimeError(f"{address} is no Dask scheduler: {said} (a web server, such as Dask's dashboard, "
                           f"answers so; the scheduler listens on another port, {DEFAULT_SCHEDULER_PORT} "
                           "unless set otherwise)")
