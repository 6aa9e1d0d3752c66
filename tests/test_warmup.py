"""restitution.warmup: every step in one or two processes, failures reported."""

import queue

import pytest

from restitution import warmup as w
from restitution.cli import main


def test_groups_cover_every_step_once():
    labels = [label for label, _ in w._steps()]
    assert len(labels) == len(set(labels)) == 15
    assert [len(g) for g in w._groups()] == [6, 9]


def test_two_processes_run_every_step():
    # the cache is warm in the test session (make env), so this measures loads, not compiles
    times = w.warmup(jobs=2)
    assert sorted(label for label, _ in times) == sorted(label for label, _ in w._steps())
    assert all(s >= 0.0 for _, s in times)


def test_a_failing_step_is_reported(monkeypatch):
    def broken():
        raise ValueError("no kernel")

    monkeypatch.setattr(w, "_groups", lambda: [[("fine", lambda: None), ("broken", broken)]])
    q = queue.Queue()
    w._run_group(0, q)
    got = [q.get_nowait() for _ in range(q.qsize())]
    assert got[0][0] == "fine" and isinstance(got[0][1], float)
    assert got[1] == ("broken", "ValueError: no kernel")
    assert got[2] is None


def test_jobs_out_of_range_is_refused(capsys):
    with pytest.raises(SystemExit):
        main(["warmup", "--jobs", "3"])
    assert "--jobs" in capsys.readouterr().err
    with pytest.raises(ValueError, match="jobs must be >= 1"):
        w.warmup(jobs=0)


def test_a_process_killed_outright_is_reported(monkeypatch):
    """A group process that dies without its end mark (a crash) fails the warmup, no hang."""

    class Killed:
        def __init__(self, target=None, args=()):
            self.exitcode = None

        def start(self):
            self.exitcode = -9

        def is_alive(self):
            return False

        def join(self):
            pass

    class Spawn:
        Process = Killed

        @staticmethod
        def Queue():  # noqa: N802 (multiprocessing's name)
            return queue.Queue()

    monkeypatch.setattr(w.multiprocessing, "get_context", lambda kind: Spawn)
    with pytest.raises(RuntimeError, match="ended with an error"):
        w.warmup(jobs=2)
