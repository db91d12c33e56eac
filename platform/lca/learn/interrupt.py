"""Stop a training at the end of the current iteration on SIGINT or SIGTERM, with its
checkpoint written, so an interrupted run loses nothing and resumes with the same command."""

from __future__ import annotations

import signal
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class TrainingInterrupted(SystemExit):
    """Not an `Exception`: the pipeline does not mark the run failed, and the exit status is
    the shell's 128 + signal number."""

    def __init__(self, signum: int, iteration: int):
        super().__init__(128 + signum)
        self.signum, self.iteration = signum, iteration

    def __str__(self) -> str:
        return (
            f"{signal.Signals(self.signum).name}: training stopped after iteration "
            f"{self.iteration}, saved in checkpoints/latest.pt; the same command resumes it"
        )


class StopOnSignal:
    """While active, the first SIGINT/SIGTERM only sets `signum` (the trainer checks it after
    each iteration); a second one acts as the handler before it would (Ctrl-C twice: at once).
    Outside the main thread, where Python cannot install handlers, it does nothing."""

    def __init__(self) -> None:
        self.signum: int | None = None
        self._previous: dict[int, object] = {}

    def __enter__(self) -> StopOnSignal:
        if threading.current_thread() is threading.main_thread():
            self._previous = {s: signal.signal(s, self._handle) for s in SIGNALS}
        return self

    def __exit__(self, *exc) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous = {}

    def _handle(self, signum: int, frame) -> None:
        if self.signum is not None:
            self.__exit__()
            signal.raise_signal(signum)
            return
        self.signum = signum
        name = signal.Signals(signum).name
        print(f"[lca] {name}: stopping after this iteration (send it again to stop at once)")
