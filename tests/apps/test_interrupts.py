"""The Ctrl-C guard of commands that save what they ran (SIGINT sent to this process)."""

from __future__ import annotations

import os
import signal

import paused_cli
import pytest

from uvms_pin.apps.interrupts import InterruptGuard


def _ctrl_c() -> None:
    os.kill(os.getpid(), signal.SIGINT)


def test_the_first_ctrl_c_raises_the_next_wait_for_the_save(capsys):
    with InterruptGuard() as guard:
        with pytest.raises(KeyboardInterrupt):
            _ctrl_c()
        with guard.saving():
            _ctrl_c()  # noted, not raised: the save goes on
            _ctrl_c()
            saved = True
        assert saved and guard.pending
        guard.release()
        _ctrl_c()  # after the save: noted, raised at the next checkpoint
        with pytest.raises(KeyboardInterrupt):
            guard.checkpoint()
    err = capsys.readouterr().err
    assert err.count("saving first, please wait") == 1
    assert err.count("stopping after this step") == 1


def test_after_the_save_a_ctrl_c_in_a_class_body_is_raised_at_the_next_checkpoint():
    """A Ctrl-C landing in an import (here a class body's ``__set_name__``) must not come
    out as a RuntimeError: it is raised at the checkpoint, between two figures."""
    with InterruptGuard() as guard:
        guard.release()
        guard.checkpoint()  # nothing noted: goes on
        defined = paused_cli.ctrl_c_in_a_class_body()
        assert defined.__name__ == "Defined"
        with pytest.raises(KeyboardInterrupt):
            guard.checkpoint()
        guard.checkpoint()  # raised once


def test_a_ctrl_c_during_a_save_raises_when_the_save_is_done():
    with InterruptGuard() as guard:
        done = []
        with pytest.raises(KeyboardInterrupt):
            with guard.saving():
                _ctrl_c()
                done.append("saved")
        assert done == ["saved"]


def test_the_previous_handler_is_back_afterwards():
    before = signal.getsignal(signal.SIGINT)
    with InterruptGuard():
        assert signal.getsignal(signal.SIGINT) is not before
    assert signal.getsignal(signal.SIGINT) is before


def test_sigterm_stops_as_ctrl_c_does_and_says_it_was_sigterm(capsys):
    """A batch system's time limit (SIGTERM): the first raises `Terminated`, a
    KeyboardInterrupt (what a run keeps on Ctrl-C it keeps); one during the save waits for
    it and is raised after it as SIGTERM; exit status 143. Outside the guard SIGTERM's own
    handling is back."""
    from uvms_pin.apps.interrupts import Terminated, stop_status

    previous = signal.getsignal(signal.SIGTERM)
    with InterruptGuard() as guard:
        with pytest.raises(Terminated) as first:
            os.kill(os.getpid(), signal.SIGTERM)
        assert stop_status(first.value) == (143, "terminated (SIGTERM)")
        guard.stopping = False  # the run's stop handled: the next one is a fresh stop
        with pytest.raises(Terminated):
            with guard.saving():
                os.kill(os.getpid(), signal.SIGTERM)
                saved = True
        assert saved
    assert signal.getsignal(signal.SIGTERM) == previous
    assert stop_status(KeyboardInterrupt()) == (130, "interrupted")
    assert "SIGTERM: saving first, please wait" in capsys.readouterr().err
