# SPDX-License-Identifier: MIT
"""POV-Ray runs for the tests, as povray-ssao makes them: POV-Ray 3.7 gives its worker thread a
few seconds to start and otherwise exits having rendered nothing ("Timed out waiting for worker
thread startup"), which a machine busy with the other suites can provoke. Such a run is the
machine's fault, not the scene's: it is run again (4 runs in all, 0.5, 1 and 2 s apart)."""

import subprocess
import time

STARTUP_TIMEOUT = "Timed out waiting for worker thread startup"


def run_povray(cmd, **kwargs):
    """subprocess.run(cmd, capture_output=True, text=True, **kwargs), run again while POV-Ray's
    worker thread did not start."""
    for attempt in range(4):
        proc = subprocess.run(cmd, capture_output=True, text=True, **kwargs)
        if STARTUP_TIMEOUT not in (proc.stderr or "") or attempt == 3:
            return proc
        time.sleep(0.5 * 2 ** attempt)
