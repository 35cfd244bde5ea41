"""The ``erodem`` command of a pip installation: runs the command-line program bundled in the
package (``erodem/bin/erodem``, built and installed by ``pip install .`` with the module), so
``erodem run config.toml`` works without the CMake build. docs/python.md.

Where no program is bundled (the package of a CMake build tree, ``build/python/erodem``), it
runs that build's ``build/cli/erodem``; ``ERODEM_CLI`` names another program.
"""

from __future__ import annotations

import os
import sys
from typing import List, Optional

#: Exit status when no program is found (sysexits EX_UNAVAILABLE).
EX_UNAVAILABLE = 69


def cli_path() -> Optional[str]:
    """The erodem program this package runs, or None: ``ERODEM_CLI``, the bundled
    ``erodem/bin/erodem``, or the CLI of the CMake build tree the package sits in."""
    here = os.path.dirname(os.path.abspath(__file__))
    exe = "erodem.exe" if os.name == "nt" else "erodem"
    candidates = [
        os.environ.get("ERODEM_CLI", ""),
        os.path.join(here, "bin", exe),
        os.path.join(os.path.dirname(os.path.dirname(here)), "cli", exe),
    ]
    for path in candidates:
        if path and os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return None


def main(argv: Optional[List[str]] = None) -> int:
    """Runs the bundled CLI with ``argv`` (default ``sys.argv[1:]``), replacing this
    process where the OS allows (its exit status, signals and terminal are the CLI's own)."""
    args = sys.argv[1:] if argv is None else list(argv)
    path = cli_path()
    if path is None:
        print(
            "erodem: the command-line program is not in this installation of the Python "
            "package (%s); reinstall with `pip install .` from the repository, build it with "
            "CMake (docs/cli.md), or set ERODEM_CLI to its path" % os.path.dirname(__file__),
            file=sys.stderr,
        )
        return EX_UNAVAILABLE
    sys.stdout.flush()
    sys.stderr.flush()
    if os.name == "nt":  # no exec on Windows
        import subprocess

        return subprocess.call([path] + args)
    os.execv(path, [path] + args)
    return 0  # not reached


if __name__ == "__main__":
    sys.exit(main())
