"""Lazy imports of native libraries with interrupts held (issue 47's interrupt contract): a
SIGINT or SIGTERM received while a module initialises waits for the import to finish, then
stops the run as an interrupt (a native module interrupted in its initialisation crashed the
process: ``rigidfold.runtime.interrupts.held_import``)."""

from __future__ import annotations

import signal
import sys

import pytest

from rigidfold.runtime.interrupts import held_import, terminate_interrupts


@pytest.fixture
def interrupting():
    """SIGINT and SIGTERM raise KeyboardInterrupt, as in a command; put back after. Both
    start from Python's defaults, whatever an earlier test in the same process left (under
    pytest-xdist the SIGINT case once inherited a handler that was not the default and raised
    nothing)."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    terminate_interrupts()
    yield
    for s, handler in saved.items():
        signal.signal(s, handler)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_the_import_waits_for_its_end(tmp_path, monkeypatch, interrupting, signum):
    name = f"_rigidfold_held_{signum.name.lower()}"
    (tmp_path / f"{name}.py").write_text(
        f"import os\nos.kill(os.getpid(), {int(signum)})\nafter_the_signal = True\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.raises(KeyboardInterrupt):
            held_import(name)
        assert sys.modules[name].after_the_signal  # the module ran to its end first
    finally:
        sys.modules.pop(name, None)


def test_without_a_signal_it_is_an_import():
    assert held_import("json") is sys.modules["json"]
