"""The ``spiral-cad`` command's entry point: Ctrl-C is handled from its first instant.

Importing ``spiral_cad`` (numpy, scipy, numba) takes about half a second,
and an interrupt then would end in a traceback, before ``spiral_cad.app.cli``
could handle it. This package imports nothing heavy: it installs the
handling, then runs ``spiral_cad.app.cli.main``.
"""

import signal
import sys
import warnings


def main() -> int:
    """Run ``spiral_cad.app.cli.main``; an interrupt while it is imported gives ``error: interrupted`` and 130."""
    received: list[int] = []

    def interrupt(signum, frame):
        received.append(signum)
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, interrupt)
    warnings.simplefilter("ignore")
    try:
        from spiral_cad.app.cli import main as run

        status = run()
    except BaseException as error:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if not (received or isinstance(error, KeyboardInterrupt)):
            raise
        print("error: interrupted", file=sys.stderr)
        return 130
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # done: an interrupt during interpreter shutdown changes nothing
    return status
