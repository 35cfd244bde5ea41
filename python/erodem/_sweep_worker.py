"""The worker process of a local sweep: ``python -m erodem._sweep_worker REQUESTS RESULTS``.

It imports only erodem (never the caller's ``__main__``, so sweeps run from scripts without
an ``if __name__ == "__main__":`` guard, from stdin and from notebooks), receives member
specs (plain data: dicts, numbers, strings, and :class:`erodem.DEM`, which pickles as its
settings or values) on the file descriptor REQUESTS, runs each with
:func:`erodem.sweep.run_member` and sends the row back on RESULTS. ``None`` ends it.
Ctrl-C is the parent's to handle (it ends the workers); the worker ignores SIGINT.
"""

from __future__ import annotations

import signal
import sys
from multiprocessing.connection import Connection


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    requests, results = Connection(int(argv[0]), writable=False), Connection(int(argv[1]),
                                                                             readable=False)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from erodem.sweep import run_member

    while True:
        try:
            spec = requests.recv()
        except EOFError:  # the parent went away
            return 0
        if spec is None:
            return 0
        results.send(run_member(spec))


if __name__ == "__main__":
    sys.exit(main())
