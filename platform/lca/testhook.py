"""A test-only interruption point, in place of killing a process from outside at the right
moment (a race on a loaded machine).

LCA_TEST_EXIT_AFTER=<event>:<n> ends the process at once with os._exit(137), the status of
a SIGKILL, right after the n-th such event: `iteration` (0-based index of a finished training
iteration, its curve row and any checkpoint written) or `round` (the n-th evaluation round
written by this process, counting from 1). Unset, it costs one environment lookup.
"""

from __future__ import annotations

import os

KILLED = 137


def exit_point(event: str, count: int) -> None:
    spec = os.environ.get("LCA_TEST_EXIT_AFTER")
    if not spec:
        return
    name, _, n = spec.partition(":")
    if name == event and n.strip() == str(count):
        os._exit(KILLED)
