"""The shared runner of the study scripts (scripts/study_runner.py): a run folder is reused only
when its summary holds the run's arguments, a failure while stepping is recorded and not run
again (for the same arguments and budget), a run resumes only from its own checkpoint, the command
is an argument vector, and the provenance and run-time lines say what they should. `bendlab` is a
stand-in program that records its arguments and writes what `bendlab shear` writes."""
import json
import math
import os
import shlex
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import study_runner as sr  # noqa: E402

FAKE = textwrap.dedent('''\
    #!/usr/bin/python3
    """Stand-in for bendlab shear: records its arguments; FAKE_MODE ok writes summary.json and
    timing.json, step fails after a step, start fails before, resume-fails refuses --resume."""
    import json, os, sys
    from pathlib import Path
    args = sys.argv[1:]
    with open(os.environ["FAKE_CALLS"], "a") as f:
        f.write(json.dumps(args) + "\\n")
    mode = os.environ.get("FAKE_MODE", "ok")
    out = Path(args[args.index("--out") + 1])
    if mode == "step" or (mode == "resume-fails" and "--resume" not in args and os.environ.get("FAKE_STEP")):
        print("bendlab: error: the run failed after step 12 (gamma t = 0.5): singular fit")
        sys.exit(1)
    if mode == "start" or (mode == "resume-fails" and "--resume" in args):
        print("bendlab: error: --resume: the checkpoint cannot be read")
        sys.exit(2)
    G = float(args[args.index("--G") + 1])
    t_end = float(args[args.index("--t-end") + 1])
    (out / "summary.json").write_text(json.dumps({"method": "C", "G": G, "t_end": t_end, "D_steady": 0.25}))
    (out / "timing.json").write_text(json.dumps({"wall_seconds": 7.0}))
''')


@dataclass(frozen=True)
class Case(sr.StudyRun):
    G: float
    t_end: float = 10.0
    tag: str = ""
    start_arguments = ("--overwrite",)

    @property
    def name(self):
        return f"C_G{sr.fmt_g(self.G)}{self.tag}"

    def arguments(self, out):
        return ["shear", "--method", "C", "--G", sr.fmt_g(self.G), "--t-end", sr.fmt_g(self.t_end),
                "--out", str(out)]

    def key(self):
        return {"method": "C", "G": self.G, "t_end": self.t_end}


@pytest.fixture
def bendlab(tmp_path, monkeypatch):
    exe = tmp_path / "bin" / "bendlab"
    exe.parent.mkdir()
    exe.write_text(FAKE)
    exe.chmod(0o755)
    monkeypatch.setenv("FAKE_CALLS", str(tmp_path / "calls.jsonl"))
    monkeypatch.delenv("FAKE_MODE", raising=False)
    return exe


def calls(tmp_path):
    path = tmp_path / "calls.jsonl"
    return [json.loads(l) for l in path.read_text().splitlines()] if path.exists() else []


def runner(bendlab, work, **kw):
    messages = []
    r = sr.Runner(bendlab, work, say=messages.append, **kw)
    r.messages = messages
    return r


def finished_folder(work, run, **fields):
    out = work / run.name
    out.mkdir(parents=True)
    (out / "summary.json").write_text(json.dumps(dict({"method": "C", "G": run.G, "t_end": run.t_end,
                                                        "D_steady": 0.3}, **fields)))
    (out / "timing.json").write_text(json.dumps({"wall_seconds": 123.0}))
    return out


# ----------------------------------------------------------------------------- keys

def test_matches_compares_numbers_to_1e12_lists_by_element_and_strings_exactly():
    key = {"method": "C", "G": 0.2, "box": [8.0, 8.0, 10.0]}
    assert sr.matches({"method": "C", "G": 0.2 * (1 + 1e-13), "box": [8, 8, 10], "other": 1}, key)
    assert not sr.matches({"method": "C", "G": 0.2 * (1 + 1e-9), "box": [8, 8, 10]}, key)
    assert not sr.matches({"method": "c", "G": 0.2, "box": [8, 8, 10]}, key)
    assert not sr.matches({"method": "C", "G": 0.2, "box": [8, 8]}, key)
    assert not sr.matches({"method": "C", "box": [8, 8, 10]}, key)  # a field it lacks
    assert not sr.matches({"method": "C", "G": "x", "box": [8, 8, 10]}, key)
    assert not sr.matches(None, key)
    assert sr.matches({"method": "C", "box": [8, 8, 10]}, key, assumed={"G": 0.2})
    assert not sr.matches({"method": "C", "box": [8, 8, 10]}, key, assumed={"G": 0.1})
    assert sr.matches({"method": "C", "G": 0.1, "box": [8, 8, 10]}, dict(key, G=0.1), assumed={"G": 0.2})


def test_the_resume_key_is_the_key_without_t_end():
    assert Case(0.2).resume_key() == {"method": "C", "G": 0.2}


# ----------------------------------------------------------------------------- the cache

def test_a_finished_run_with_the_same_arguments_is_taken_from_its_folder(tmp_path, bendlab):
    run = Case(0.2)
    finished_folder(tmp_path / "work", run)
    study = runner(bendlab, tmp_path / "work")
    result = study.execute(run)
    assert result.ok and result.cached
    assert result.summary["wall_seconds"] == 123.0  # from timing.json
    assert calls(tmp_path) == []


def test_a_folder_of_other_arguments_is_run_again_from_scratch(tmp_path, bendlab):
    run = Case(0.2)
    out = finished_folder(tmp_path / "work", run, G=0.1)
    (out / "stale.txt").write_text("from the earlier run")
    result = runner(bendlab, tmp_path / "work").execute(run)
    assert result.ok and not result.cached
    assert result.summary["G"] == 0.2 and result.summary["wall_seconds"] == 7.0
    assert not (out / "stale.txt").exists()
    assert len(calls(tmp_path)) == 1


def test_a_summary_to_another_t_end_is_no_cache_hit(tmp_path, bendlab):
    finished_folder(tmp_path / "work", Case(0.2, t_end=4.0), t_end=4.0)
    assert runner(bendlab, tmp_path / "work").cached(Case(0.2, t_end=4.0)) is not None
    finished_folder(tmp_path / "work2", Case(0.2), t_end=4.0)
    assert runner(bendlab, tmp_path / "work2").cached(Case(0.2)) is None


def test_the_wall_time_comes_from_timing_json_else_the_summary_else_nan(tmp_path):
    (tmp_path / "summary.json").write_text(json.dumps({"wall_seconds": 5}))
    assert sr.read_summary(tmp_path)["wall_seconds"] == 5.0
    (tmp_path / "timing.json").write_text(json.dumps({"wall_seconds": 9}))
    assert sr.read_summary(tmp_path)["wall_seconds"] == 9.0
    (tmp_path / "summary.json").write_text("{}")
    (tmp_path / "timing.json").write_text("{")
    assert math.isnan(sr.read_summary(tmp_path)["wall_seconds"])
    (tmp_path / "summary.json").write_text("{")
    assert sr.read_summary(tmp_path) is None


def test_read_series_gives_the_columns_or_none(tmp_path):
    assert sr.read_series(tmp_path) is None
    (tmp_path / "timeseries.csv").write_text("gamma_t,D,theta\n0,0,0.7\n0.5,0.1,0.6\n")
    s = sr.read_series(tmp_path, ("gamma_t", "D"))
    assert set(s) == {"gamma_t", "D"} and list(s["D"]) == [0.0, 0.1]
    assert set(sr.read_series(tmp_path)) == {"gamma_t", "D", "theta"}
    (tmp_path / "timeseries.csv").write_text("gamma_t,D\n")
    assert sr.read_series(tmp_path) is None


# ----------------------------------------------------------------------------- commands

def test_the_command_is_an_argument_vector_and_the_log_starts_with_it(tmp_path, bendlab):
    run = Case(0.05, tag="; touch INJECTED 'x y'")
    work = tmp_path / "work $(dir)"
    result = runner(bendlab, work).execute(run)
    assert result.ok
    out = work / run.name
    expected = sr.command(bendlab, run, out)
    assert expected == [str(bendlab), "shear", "--method", "C", "--G", "0.05", "--t-end", "10", "--out",
                        str(out), "--overwrite"]
    assert calls(tmp_path) == [expected[1:]]  # one argument each, nothing read by a shell
    assert not (Path.cwd() / "INJECTED").exists() and not (sr.ROOT / "INJECTED").exists()
    assert (out / "run.log").read_text().splitlines()[0] == "$ " + shlex.join(expected)


def test_resume_replaces_the_start_arguments():
    run = Case(0.2)
    assert sr.command("b", run, "o", resume=True)[-1] == "--resume"
    assert "--overwrite" not in sr.command("b", run, "o", resume=True)
    assert sr.command("b", run, "o")[-1] == "--overwrite"


def test_a_run_resumes_from_its_own_checkpoint_only(tmp_path, bendlab):
    work = tmp_path / "work"
    own, other = Case(0.2), Case(0.1)
    for run, G in ((own, 0.2), (other, 0.3)):
        (work / run.name).mkdir(parents=True)
        (work / run.name / "checkpoint.json").write_text(json.dumps({"arguments": {"method": "C", "G": G},
                                                                     "time": 2.5}))
    study = runner(bendlab, work)
    assert study.state(own)[0] == "resume" and study.state(other)[0] == "run"
    study.execute(own)
    study.execute(other)
    first, second = calls(tmp_path)
    assert first[-1] == "--resume" and second[-1] == "--overwrite"
    assert not (work / other.name / "checkpoint.json").exists()  # the other run's folder was cleared


def test_a_resume_that_fails_at_its_start_starts_over(tmp_path, bendlab, monkeypatch):
    work = tmp_path / "work"
    run = Case(0.2)
    (work / run.name).mkdir(parents=True)
    (work / run.name / "checkpoint.json").write_text(json.dumps({"arguments": {"method": "C", "G": 0.2}}))
    monkeypatch.setenv("FAKE_MODE", "resume-fails")
    result = runner(bendlab, work).execute(run)
    assert result.ok
    assert [c[-1] for c in calls(tmp_path)] == ["--resume", "--overwrite"]


def test_a_folder_another_run_holds_is_neither_cleared_nor_run(tmp_path, bendlab):
    # bendlab holds <folder>/.lock with flock() for the whole of a run; a second study process
    # must not delete that folder (the first run would go on writing beside a second one)
    import fcntl
    work = tmp_path / "work"
    fresh, resumable = Case(0.2), Case(0.1)
    out = finished_folder(work, fresh, G=0.3)  # another run's files: would be cleared
    resume_out = work / resumable.name
    resume_out.mkdir()
    (resume_out / "checkpoint.json").write_text(json.dumps({"arguments": {"method": "C", "G": 0.1}}))
    held = []
    for folder in (out, resume_out):
        (folder / ".lock").touch()
        f = open(folder / ".lock")
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        held.append(f)
    study = runner(bendlab, work)
    assert sr.in_use(out) and sr.in_use(resume_out) and not sr.in_use(tmp_path)
    for run in (fresh, resumable):
        result = study.execute(run)
        assert not result.ok and result.error == "in use by another run"
    assert (out / "summary.json").exists() and (resume_out / "checkpoint.json").exists()
    assert calls(tmp_path) == []
    assert sum("in use by another run" in m for m in study.messages) == 2
    for f in held:
        f.close()
    assert not sr.in_use(out)
    assert study.execute(fresh).ok  # released: the folder is run again


# ----------------------------------------------------------------------------- failed runs

def test_a_failure_while_stepping_is_recorded_and_not_run_again(tmp_path, bendlab, monkeypatch):
    work, run = tmp_path / "work", Case(0.2)
    monkeypatch.setenv("FAKE_MODE", "step")
    first = runner(bendlab, work, failure_fields={"max_steps": 100}).execute(run)
    assert not first.ok and "failed after step 12" in first.error
    record = json.loads((work / run.name / "failed.json").read_text())
    assert record == {"arguments": run.arguments("OUT"), "max_steps": 100, "error": first.error}

    monkeypatch.setenv("FAKE_MODE", "ok")
    again = runner(bendlab, work, failure_fields={"max_steps": 100})
    assert again.state(run) == ("failed", first.error)
    second = again.execute(run)
    assert not second.ok and second.cached and second.error == first.error
    assert len(calls(tmp_path)) == 1

    # Another budget, or other arguments in the same folder, run again.
    assert runner(bendlab, work, failure_fields={"max_steps": 200}).execute(run).ok
    assert len(calls(tmp_path)) == 2


def test_a_failure_at_the_start_is_not_recorded(tmp_path, bendlab, monkeypatch):
    work, run = tmp_path / "work", Case(0.2)
    monkeypatch.setenv("FAKE_MODE", "start")
    result = runner(bendlab, work).execute(run)
    assert not result.ok and "--resume" in result.error
    assert not (work / run.name / "failed.json").exists()
    monkeypatch.setenv("FAKE_MODE", "ok")
    assert runner(bendlab, work).execute(run).ok


@pytest.mark.parametrize("text", ["", "{", "[]", json.dumps({"error": 3}),
                                  json.dumps({"arguments": ["x"], "error": "e"})])
def test_a_damaged_or_foreign_record_is_no_failure(tmp_path, text):
    (tmp_path / "failed.json").write_text(text)
    assert sr.read_failure(tmp_path, sr.failure_identity(Case(0.2))) is None


def test_only_failures_of_the_steps_count_as_such():
    assert sr.failed_while_stepping("bendlab: error: the run failed after step 51807 (gamma t = 4.23): x")
    assert not sr.failed_while_stepping("bendlab: error: --resume: no checkpoint in 'x' to resume from")
    assert not sr.failed_while_stepping(None)


# ----------------------------------------------------------------------------- the pool and the list

def test_run_all_runs_each_run_once_and_keeps_their_order(tmp_path, bendlab):
    runs = [Case(G) for G in (0.3, 0.1, 0.2)]
    finished_folder(tmp_path / "work", runs[1])
    results = runner(bendlab, tmp_path / "work", jobs=2).run_all(runs + [runs[0]])
    assert list(results) == runs
    assert all(r.ok for r in results.values())
    assert [r.cached for r in results.values()] == [False, True, False]
    assert sorted(c[c.index("--G") + 1] for c in calls(tmp_path)) == ["0.2", "0.3"]


def test_list_runs_nothing_and_says_the_state_and_command_of_each(tmp_path, bendlab):
    work = tmp_path / "work"
    finished_folder(work, Case(0.1))
    study = runner(bendlab, work)
    study.list([Case(0.1), Case(0.2)], "a study")
    text = "\n".join(study.messages)
    assert "C_G0.1: done" in text and "C_G0.2: to run" in text
    assert "$ " + shlex.join(sr.command(bendlab, Case(0.2), work / Case(0.2).name)) in text
    assert text.splitlines()[-1] == "1 done, 0 failed, 0 to resume from a checkpoint, 1 to run"
    assert calls(tmp_path) == []


# ----------------------------------------------------------------------------- provenance and run times

def test_the_invocation_names_the_script_from_the_repository_quoted_for_a_shell():
    line = sr.invocation(sr.ROOT / "scripts" / "shear_study.py", ["--only", "e", "--doc", "a b.md"])
    assert line == "/usr/bin/python3 scripts/shear_study.py --only e --doc 'a b.md'"
    assert sr.generated_by(line) == ["Generated by", "", "    " + line, ""]


def test_the_machine_line_names_cores_and_system():
    text = sr.machine()
    assert text.startswith(f"{len(os.sched_getaffinity(0))} cores (nproc)")
    assert text.endswith(f"{os.uname().sysname} {os.uname().machine}")


def test_the_source_commit_is_marked_only_for_changes_outside_the_results(tmp_path, monkeypatch):
    def git(*args):
        subprocess.run(["git", *args], cwd=tmp_path, check=True, capture_output=True)
    git("init", "-q")
    (tmp_path / "src.py").write_text("a\n")
    (tmp_path / "docs" / "results").mkdir(parents=True)
    (tmp_path / "docs" / "results" / "x.md").write_text("a\n")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "x")
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tmp_path, capture_output=True,
                          text=True).stdout.strip()
    monkeypatch.setattr(sr, "ROOT", tmp_path)
    assert sr.source_commit() == head
    (tmp_path / "docs" / "results" / "x.md").write_text("b\n")
    assert sr.source_commit() == head
    (tmp_path / "src.py").write_text("b\n")
    assert sr.source_commit() == head + " with uncommitted changes"


def test_the_run_time_table_has_a_row_per_run_and_marks_failed_and_missing_ones():
    ok = sr.Result(Case(0.1), {"wall_seconds": 12.4, "steps": 30})
    bad = sr.Result(Case(0.2), None, error="the run failed after step 3")
    entries = [(["0.1"], ok), (["0.2"], bad), (["0.3"], None)]
    columns = [("wall s", lambda s: f"{s['wall_seconds']:.0f}"), ("steps", lambda s: str(s["steps"]))]
    assert sr.run_time_table(["G"], entries, columns, total="| **all** | **12** | |") == [
        "| G | wall s | steps |", "| --- | --- | --- |", "| 0.1 | 12 | 30 |", "| 0.2 | failed | |",
        "| 0.3 | not run | |", "| **all** | **12** | |"]
    lines = sr.run_time_table(["G"], entries, columns, missing=None, failure=lambda r: "failed: " + r.error)
    assert lines[2:] == ["| 0.1 | 12 | 30 |", "| 0.2 | failed: the run failed after step 3 | |"]


def test_the_total_wall_time_leaves_out_unknown_times():
    assert sr.total_wall([{"wall_seconds": 2.0}, None, {"wall_seconds": math.nan}, {"wall_seconds": 3}]) == 5.0
    assert sr.total_wall([]) == 0


def test_the_program_of_a_run_is_the_first_word_of_its_latest_command_line(tmp_path):
    (tmp_path / "run.log").write_text("$ /tmp/old/bendlab shear --out x\nstep 1\n$ '/tmp/new dir/bendlab' shear --resume\nstep 2\n")
    assert sr.binary_of(tmp_path) == "/tmp/new dir/bendlab"
    assert sr.binary_of(tmp_path / "none") is None


def test_the_launch_line_names_the_thread_count_and_the_program_after_it(tmp_path, monkeypatch):
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    assert sr.launch_environment() == "OMP_NUM_THREADS=2 "
    monkeypatch.delenv("OMP_NUM_THREADS")
    assert sr.launch_environment() == ""
    (tmp_path / "run.log").write_text("$ /tmp/a/bendlab flow --out x\nt = 1\n"
                                      "$ OMP_NUM_THREADS=2 '/tmp/b dir/bendlab' flow --resume\nt = 2\n")
    assert sr.binary_of(tmp_path) == "/tmp/b dir/bendlab"
    assert sr.threads_of(tmp_path) == [None, "2"]
    assert sr.threads_of(tmp_path / "none") == []
    # Only the leading assignments are the environment: a later word with '=' is the program's.
    assert sr.split_environment(["A=1", "B_2=x", "prog", "C=3"]) == ({"A": "1", "B_2": "x"}, ["prog", "C=3"])
