"""The runs of a study, shared by every study script (shear_study.py, lbm_study.py,
small_g_study.py, rbc_shear_study.py): the cache of run folders keyed by a run's arguments, the
`bendlab` command of a run, the record of a failed run, the pool that runs them, and the parts of
a document that say where it came from and what its runs cost. A study script holds its cases,
figures and tables.

A run is any object with (StudyRun gives the defaults):
  name               its folder under the work folder
  arguments(out)     the `bendlab` arguments writing into the folder `out` (without --resume)
  key()              the fields of summary.json that a finished run of these arguments holds:
                     numbers compared to 1e-12 (relative), lists element by element, the rest equal
  resume_key()       the fields of checkpoint.json's "arguments" for resuming it (default: key()
                     without t_end)
  assumed()          values taken for fields an older summary or checkpoint lacks
  start_arguments    appended when the run starts afresh (not when it resumes)
  label()            the run in progress lines

A run folder holds what `bendlab shear` writes: summary.json when finished (with timing.json's
wall_seconds), checkpoint.json to resume from, run.log (its first line the command) and, for a run
that failed while stepping (deterministic: a rerun repeats it), failed.json, which keeps the study
from starting it again until the folder is deleted.
"""
import csv
import fcntl
import json
import math
import os
import platform
import re
import shlex
import shutil
import signal
import subprocess
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
PYTHON = "/usr/bin/python3"


def fmt_g(x):
    """A number as it appears in folder names and on the command line."""
    return f"{x:g}"


def standard_errors_apart(a, b):
    """(difference of two summary entries in their combined standard errors, the difference)."""
    d = a["mean"] - b["mean"]
    se = math.hypot(a["standard_error"], b["standard_error"])
    return (d / se if se > 0 else math.inf), d


# The tube study's reference case (scripts/tube_study.py: D = 10 um, 20 um periodic, dx = 0.5 um,
# tau = 1.82, pseudo-shear rate 100 1/s, H_T 0.3, seed 1, Method C with its net force kept,
# mt1:1280), which the time-scaling and membrane-every studies vary.
TUBE_REFERENCE_KEY = {"diameter_um": 10.0, "hematocrit": 0.3, "method": "C", "mesh": "mt1:1280", "tau": 1.82,
                      "dx_um": 0.5, "pseudo_shear_rate": 100.0, "seed": 1}


def tube_reference_arguments(extra, t_end, out):
    """`bendlab flow`'s arguments for the reference case with `extra` options, to t_end, into out."""
    return (["flow", "--geometry", "tube", "--diameter", "10", "--length", "20", "--dx", "0.5", "--tau", "1.82",
             "--pseudo-shear-rate", "100", "--hematocrit", "0.3", "--seed", "1", "--method", "C",
             "--bending-net-force", "keep", "--mesh", "mt1:1280"] + list(extra)
            + ["--t-end", fmt_g(t_end), "--sample-every", "0.0001", "--snapshot-every", "0.01", "--out", str(out)])


def close(a, b):
    """Whether two numbers agree to 1e-12 (relative, absolute below 1); False where one is None."""
    return a is not None and b is not None and abs(float(a) - float(b)) <= 1e-12 * max(1.0, abs(float(b)))


def _same(have, want):
    if isinstance(want, bool) or want is None or isinstance(want, str):
        return have == want
    if isinstance(want, (int, float)):
        return close(have, want)
    if isinstance(want, (list, tuple)):
        return (isinstance(have, (list, tuple)) and len(have) == len(want)
                and all(_same(h, w) for h, w in zip(have, want)))
    return have == want


_MISSING = object()


def matches(record, key, assumed=None):
    """Whether the dict `record` (a summary.json, or a checkpoint's arguments) holds every field of
    `key`; a field it lacks is taken from `assumed` (what older runs did not write)."""
    if not isinstance(record, dict):
        return False
    assumed = assumed or {}
    try:
        for name, want in key.items():
            have = record.get(name, assumed.get(name, _MISSING))
            if have is _MISSING or not _same(have, want):
                return False
        return True
    except (TypeError, ValueError):
        return False


class StudyRun:
    """Defaults of a study's run (see the module's description)."""
    start_arguments = ()

    def key(self):
        return {"t_end": self.t_end}

    def resume_key(self):
        return {k: v for k, v in self.key().items() if k != "t_end"}

    def assumed(self):
        return {}

    def label(self):
        return self.name


# ----------------------------------------------------------------------------- run folders

def read_json(path):
    """A JSON file's content, or None where it is missing or damaged."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def read_summary(folder):
    """summary.json of a run folder with `wall_seconds` from timing.json beside it (which adds up
    the parts of a resumed run; else the summary's own, else NaN), or None."""
    summary = read_json(Path(folder) / "summary.json")
    if not isinstance(summary, dict):
        return None
    try:
        summary["wall_seconds"] = float(read_json(Path(folder) / "timing.json")["wall_seconds"])
    except (TypeError, KeyError, ValueError):
        try:
            summary["wall_seconds"] = float(summary.get("wall_seconds", math.nan))
        except (TypeError, ValueError):
            summary["wall_seconds"] = math.nan
    return summary


def read_series(folder, columns=None):
    """timeseries.csv of a run folder: column -> numpy array (`columns`, or all), or None where
    the file is missing or has no rows."""
    try:
        with open(Path(folder) / "timeseries.csv", newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError:
        return None
    if not rows:
        return None
    return {k: np.array([number(r[k]) for r in rows]) for k in (columns or rows[0].keys())}


def number(field):
    """A field of bendlab's CSV files: an empty one is an undefined value (NaN)."""
    return float(field) if field != "" else float("nan")


def number_list(text, option, valid, requirement):
    """The comma-separated numbers of a command-line option, each of which `valid` accepts; else the
    script exits with an error naming the option and `requirement` (what every number must be)."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise SystemExit(f"error: {option}: not a list of numbers: '{text}'")
    if not values or any(not (valid(v) and math.isfinite(v)) for v in values):
        raise SystemExit(f"error: {option}: every {requirement}: '{text}'")
    return values


def finished(folder, run):
    """The summary of the finished run `run` in `folder` (its arguments match), else None."""
    summary = read_summary(folder)
    return summary if summary is not None and matches(summary, run.key(), run.assumed()) else None


def checkpoint(folder, run):
    """The checkpoint in `folder` that `run` resumes from (its arguments match), else None."""
    cp = read_json(Path(folder) / "checkpoint.json")
    if not isinstance(cp, dict) or not matches(cp.get("arguments"), run.resume_key(), run.assumed()):
        return None
    return cp


def rel(path):
    """A path as a document names it: relative to the repository where it lies inside."""
    try:
        return str(Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


# ----------------------------------------------------------------------------- failed runs

def failed_while_stepping(error):
    """Whether `error` is a failure of the run's own steps (not of its start, files or resume)."""
    return "the run failed after step" in (error or "")


def failure_identity(run, **fields):
    """What a failed.json must hold to be the record of `run`: its arguments (with the folder
    written as OUT) and `fields` (a study's budget, e.g. max_steps)."""
    return {"arguments": list(run.arguments("OUT")), **fields}


def write_failure(folder, identity, error):
    """failed.json: the run of `identity` failed while stepping with `error`."""
    tmp = Path(folder) / "failed.json.tmp"
    tmp.write_text(json.dumps(dict(identity, error=error), indent=1) + "\n")
    os.replace(tmp, Path(folder) / "failed.json")


def read_failure(folder, identity):
    """The error of a recorded failure of exactly the run of `identity`, else None."""
    record = read_json(Path(folder) / "failed.json")
    if not isinstance(record, dict) or not isinstance(record.get("error"), str):
        return None
    if {k: record.get(k) for k in identity} != identity:
        return None
    return record["error"]


# ----------------------------------------------------------------------------- commands

def in_use(folder):
    """Whether another process holds the run folder's lock (the flock() on <folder>/.lock that
    bendlab takes for the whole of a run, core/folder_lock.hpp). Such a folder is not cleared:
    deleting it under a running bendlab would let a second run write beside the first."""
    lock = Path(folder) / ".lock"
    try:
        fd = os.open(lock, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        fcntl.flock(fd, fcntl.LOCK_UN)
        return False
    except BlockingIOError:
        return True
    finally:
        os.close(fd)


def bendlab_binary(path):
    """The `bendlab` executable at `path` (relative to the current folder), as an absolute path;
    exits with a message saying how to build it where there is none."""
    binary = Path(path)
    if not binary.is_absolute():
        binary = (Path.cwd() / binary).resolve()
    if not (binary.is_file() and os.access(binary, os.X_OK)):
        raise SystemExit(f"error: no bendlab binary at '{path}' (build it: cmake --preset release && "
                         "cmake --build --preset release, or pass --bendlab PATH)")
    return binary


def command(bendlab, run, out, resume=False):
    """The argument vector that runs `run` into `out` (continuing from its checkpoint if resume)."""
    return ([str(bendlab)] + [str(a) for a in run.arguments(out)]
            + (["--resume"] if resume else [str(a) for a in run.start_arguments]))


def last_line(path):
    try:
        lines = [l for l in Path(path).read_text().splitlines() if l.strip()]
    except OSError:
        return ""
    return lines[-1] if lines else ""


class Stopped(Exception):
    """The study was stopped; the run did not finish."""


@dataclass
class Result:
    run: object
    summary: dict | None = None
    error: str | None = None
    cached: bool = False  # taken from the work folder, not run now
    series: dict = field(default_factory=dict)  # what a study loads of the run's time series

    @property
    def ok(self):
        return self.summary is not None


class Runner:
    """Runs a study's runs in `work` (each in work / run.name) with `bendlab`, `jobs` at a time:
    a finished run whose summary matches its key is taken from the folder, a recorded failure is
    not run again, an interrupted run continues from its checkpoint. `failure_fields` join a
    failure's identity (a study's step budget). Progress goes to `say`."""

    def __init__(self, bendlab, work, jobs=1, failure_fields=None, progress_every=60.0, say=None):
        self.bendlab = bendlab
        self.work = Path(work)
        self.jobs = jobs
        self.failure_fields = dict(failure_fields or {})
        self.progress_every = progress_every
        self._print_lock = threading.Lock()
        self._say = say
        self._live = set()
        self._live_lock = threading.Lock()
        self._stopping = threading.Event()
        self._count = 0

    def say(self, msg):
        with self._print_lock:
            (self._say or (lambda m: print(m, flush=True)))(msg)

    def folder(self, run):
        return self.work / run.name

    def identity(self, run):
        return failure_identity(run, **self.failure_fields)

    def state(self, run):
        """('done', summary), ('failed', error), ('resume', checkpoint) or ('run', None): what
        execute() does with the run."""
        out = self.folder(run)
        summary = read_summary(out)
        if summary is not None and matches(summary, run.key(), run.assumed()):
            return "done", summary
        if summary is None:
            error = read_failure(out, self.identity(run))
            if error is not None:
                return "failed", error
            cp = checkpoint(out, run) if out.is_dir() else None
            if cp is not None:
                return "resume", cp
        return "run", None

    def cached(self, run):
        """The run's Result from its folder when it is finished or recorded as failed, else None."""
        state, info = self.state(run)
        if state == "done":
            return Result(run, info, cached=True)
        if state == "failed":
            return Result(run, None, error=info, cached=True)
        return None

    def _next(self):
        with self._print_lock:
            self._count += 1
            return self._count

    @staticmethod
    def _facts(s):
        facts = []
        if isinstance(s.get("D_steady"), (int, float)):
            facts.append(f"D_steady {s['D_steady']:.4f}")
        if isinstance(s.get("mean_gamma_dt"), (int, float)):
            facts.append(f"mean gamma dt {s['mean_gamma_dt']:.3g}")
        if "steps" in s:
            facts.append(f"{s['steps']} steps")
        return ", ".join(facts + [f"{s['wall_seconds']:.0f} s"])

    def execute(self, run, total=1):
        """Runs (or takes from its folder, or resumes) one run; returns its Result."""
        state, info = self.state(run)
        if state == "done":
            self.say(f"[{self._next():2d}/{total}] cached   {run.label()}: {self._facts(info)}")
            return Result(run, info, cached=True)
        out = self.folder(run)
        if state == "failed":
            self.say(f"[{self._next():2d}/{total}] cached   {run.label()}: FAILED ({info}; delete {out} "
                     "to run it again)")
            return Result(run, None, error=info, cached=True)
        if in_use(out):
            self.say(f"[{self._next():2d}/{total}] skipped  {run.label()}: its folder {out} is in use by another run")
            return Result(run, None, error="in use by another run")
        resume = state == "resume"
        if not resume and out.exists():
            shutil.rmtree(out)
        out.mkdir(parents=True, exist_ok=True)
        self.say(f"[  /{total}] {'resume ' if resume else 'start  '}  {run.label()}")
        start = time.monotonic()
        rc, err = self.launch(command(self.bendlab, run, out, resume), out)
        if rc != 0 and resume and not failed_while_stepping(err) and not in_use(out):
            self.say(f"[  /{total}] resume failed, starting over: {run.label()}")
            shutil.rmtree(out)
            out.mkdir(parents=True)
            rc, err = self.launch(command(self.bendlab, run, out, False), out)
        elapsed = time.monotonic() - start
        summary = finished(out, run)
        n = self._next()
        if rc != 0 or summary is None:
            err = err or f"exit status {rc}"
            self.say(f"[{n:2d}/{total}] FAILED   {run.label()} (exit {rc}, {elapsed:.0f} s): {err}")
            if failed_while_stepping(err):
                write_failure(out, self.identity(run), err)
            return Result(run, None, error=err)
        self.say(f"[{n:2d}/{total}] done     {run.label()}: {self._facts(summary)}")
        return Result(run, summary)

    def launch(self, cmd, out):
        """Runs the argument vector `cmd` in the repository with its output appended to
        out/run.log (after a line `$ command`); returns (exit status, last line of the log when
        it failed). Raises Stopped when the study is being stopped."""
        with open(Path(out) / "run.log", "a") as log:
            log.write("$ " + launch_environment() + shlex.join(cmd) + "\n")
            log.flush()
            with self._live_lock:
                if self._stopping.is_set():
                    raise Stopped()
                proc = subprocess.Popen(cmd, stdout=log, stderr=log, cwd=ROOT, start_new_session=True)
                self._live.add((proc, Path(out)))
            try:
                rc = proc.wait()
            finally:
                with self._live_lock:
                    self._live.discard((proc, Path(out)))
        if self._stopping.is_set():
            raise Stopped()
        return rc, (last_line(Path(out) / "run.log") if rc != 0 else "")

    def report_running(self, elapsed):
        """One line per running run: its latest progress line."""
        with self._live_lock:
            dirs = sorted(out for _, out in self._live)
        for d in dirs:
            last = last_progress_line(d)
            self.say(f"  [{elapsed / 60:5.1f} min] {d.name}: {' '.join(last.split()) or 'starting'}")

    def stop(self):
        """No new runs; the running ones are terminated (they keep their last checkpoint)."""
        with self._live_lock:
            self._stopping.set()
            for proc, _ in self._live:
                proc.terminate()

    def run_all(self, runs):
        """Runs `runs` (in this order, `jobs` at a time) and returns run -> Result. Interrupted
        (Ctrl-C, SIGTERM), it stops the running ones, says how to go on and exits with 130."""
        runs = list(dict.fromkeys(runs))
        results = {}
        main = threading.current_thread() is threading.main_thread()

        def on_sigterm(signum, frame):
            raise KeyboardInterrupt()
        previous = signal.signal(signal.SIGTERM, on_sigterm) if main else None
        start = time.monotonic()
        pool = ThreadPoolExecutor(max_workers=self.jobs)
        try:
            futures = {pool.submit(self.execute, r, len(runs)): r for r in runs}
            pending = set(futures)
            while pending:
                done, pending = wait(pending, timeout=self.progress_every, return_when=FIRST_COMPLETED)
                for f in done:
                    results[futures[f]] = f.result()
                if not done:
                    self.report_running(time.monotonic() - start)
        except KeyboardInterrupt:
            self.stop()
            pool.shutdown(wait=True, cancel_futures=True)
            self.say("interrupted: finished runs are kept and running ones continue from their last "
                     "checkpoint; run the same command again to go on")
            raise SystemExit(130)
        finally:
            if main:
                signal.signal(signal.SIGTERM, previous)
        pool.shutdown(wait=True)
        return {r: results[r] for r in runs}

    def list(self, runs, what):
        """Prints the runs, the state of each and its command (as it is, or was, started); runs
        nothing."""
        runs = list(runs)
        self.say(f"{what}: {len(runs)} runs, in the order they are started; work folder {self.work}")
        counts = {"done": 0, "failed": 0, "resume": 0, "run": 0}
        for run in runs:
            state, info = self.state(run)
            counts[state] += 1
            cmd = command(self.bendlab, run, self.folder(run), state == "resume")
            if state == "done":
                evaluations = info.get("velocity_evaluations")
                note = f"done: {self._facts(info)}" + (f", {evaluations} evaluations" if evaluations else "")
            elif state == "failed":
                note = f"failed, not run again until its folder is deleted: {info}"
            elif state == "resume":
                t = info.get("time")
                at = (f" at gamma t = {t:.3g} of {fmt_g(run.t_end)}" if isinstance(t, (int, float))
                      and hasattr(run, "t_end") else "")
                note = f"resumes{at} ({float(info.get('wall_seconds') or 0):.0f} s so far)"
            else:
                note = "to run"
            self.say(f"  {run.label()}: {note}\n      $ {shlex.join(cmd)}")
        self.say(f"{counts['done']} done, {counts['failed']} failed, {counts['resume']} to resume from a "
                 f"checkpoint, {counts['run']} to run")
        return 0


# ----------------------------------------------------------------------------- provenance

def invocation(script, argv):
    """The command line that regenerates a document: the interpreter, the script (relative to
    the repository) and its arguments, quoted for a shell."""
    return f"{PYTHON} {rel(script)}" + "".join(" " + shlex.quote(a) for a in argv)


def source_commit():
    """The short hash of HEAD, marked when tracked files other than results (docs/results, studies)
    differ from it: a study's own outputs do not make its source uncommitted ('' outside git)."""
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                                text=True).stdout.strip()
        if commit and subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".",
                                      ":!docs/results", ":!studies"], cwd=ROOT,
                                     capture_output=True, text=True).stdout.strip():
            commit += " with uncommitted changes"
        return commit
    except OSError:
        return ""


def cores():
    return len(os.sched_getaffinity(0))


def machine():
    """'2 cores (nproc), CPU model, Linux x86_64'."""
    cpu = ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cores()} cores (nproc){', ' + cpu if cpu else ''}, {platform.system()} {platform.machine()}"


def launch_environment():
    """What of the environment a run's time depends on, as the `$ command` line of run.log names it
    (`OMP_NUM_THREADS=N `, or nothing where it is not set)."""
    threads = os.environ.get("OMP_NUM_THREADS")
    return f"OMP_NUM_THREADS={shlex.quote(threads)} " if threads else ""


def launch_lines(folder):
    """The words of each `$ command` line of a run's run.log (launch() writes one before each start
    or resume), the environment assignments first, oldest first; [] without a log."""
    try:
        lines = (Path(folder) / "run.log").read_text(errors="replace").splitlines()
    except OSError:
        return []
    return [shlex.split(line[2:]) for line in lines if line.startswith("$ ")]


def last_progress_line(folder):
    """The latest progress line of a run's run.log ("" without one): shear's start "gamma t =",
    flow's and the others' "t ="."""
    try:
        lines = (Path(folder) / "run.log").read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return next((line for line in reversed(lines) if line.startswith(("gamma t =", "t ="))), "")


def split_environment(words):
    """A `$ command` line's words as (its leading VAR=value assignments as a dict, the rest)."""
    env = {}
    while words and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[0]):
        name, value = words[0].split("=", 1)
        env[name] = value
        words = words[1:]
    return env, words


def binary_of(folder):
    """The program that made a run: the first word after the environment of its run.log's latest
    `$ command` line, or None."""
    for words in reversed(launch_lines(folder)):
        rest = split_environment(words)[1]
        return rest[0] if rest else None
    return None


def threads_of(folder):
    """The OMP_NUM_THREADS each start of a run named on its `$ command` line, oldest first (None for
    a start whose line names none: lines written before it was recorded)."""
    return [split_environment(words)[0].get("OMP_NUM_THREADS") for words in launch_lines(folder)]


def generated_by(command_line):
    """The lines that open a document or section: the command that wrote it."""
    return ["Generated by", "", f"    {command_line}", ""]


# ----------------------------------------------------------------------------- run times

def total_wall(summaries):
    """The run time of the finished runs together: the sum of their wall_seconds where known."""
    return sum(s["wall_seconds"] for s in summaries
               if s is not None and math.isfinite(float(s.get("wall_seconds", math.nan))))


def run_time_table(head, entries, columns, total=None, missing="not run",
                   failure=lambda result: "failed"):
    """A Markdown table of run times. head: the names of the columns that identify a run;
    entries: (cells, result) with the run's identifying cells and its Result (None: not run);
    columns: (name, format) of the measured columns, format(summary) giving the cell. A failed
    run shows failure(result) in the first measured column, a run not run `missing` (None: no
    row). total: a last line, as it is."""
    width = len(head) + len(columns)
    lines = ["| " + " | ".join(list(head) + [name for name, _ in columns]) + " |", "|" + " --- |" * width]
    for cells, result in entries:
        if result is None and missing is None:
            continue
        if result is None or not result.ok:
            text = missing if result is None else failure(result)
            lines.append("| " + " | ".join(list(cells) + [text]) + " |" + " |" * (len(columns) - 1))
            continue
        lines.append("| " + " | ".join(list(cells) + [fmt(result.summary) for _, fmt in columns]) + " |")
    if total is not None:
        lines.append(total)
    return lines
