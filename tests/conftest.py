"""Suite-wide set-up: Ctrl-C reaches the tests' processes however the suite was started.

A shell without job control starts a background job (``cmd &``, ``nohup cmd &``) with SIGINT
ignored, and Python then leaves it ignored, in pytest and in every child it starts: the
suite's Ctrl-C tests (a SIGINT to a child ``chaoscam`` process, or raised inside this one)
would fail there although the code is right, since a ``chaoscam`` started with SIGINT ignored
rightly keeps ignoring it. Measured: the whole suite run as ``nohup python -m pytest &``
failed those 7 tests; with this hook all 1,062 pass (in the foreground, or under ``timeout``,
which hands SIGINT on at its default, they always passed). So the suite restores Python's
own handler; a handler set here is reset to the default in every child at exec, so the
children install Python's handler too."""

import signal


def pytest_configure(config):
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
