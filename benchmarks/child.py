"""Run one benchmark case in a fresh Python process, so its time and peak memory are its own
(no kernels, bases or arrays left by an earlier case)."""

import json
import subprocess
import sys
from pathlib import Path


def run_case_in_child(module: str, *args) -> dict:
    """``module.run_case(*args)`` (a benchmark script beside this file) in a fresh process;
    the JSON of the dict it returns, printed as its last line of stdout. RuntimeError with
    the end of its stderr if it fails."""
    here = str(Path(__file__).parent)
    call = ", ".join(repr(a) for a in args)
    code = (f"import json, sys; sys.path.insert(0, {here!r}); import {module} as b; "
            f"print(json.dumps(b.run_case({call})))")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(done.stderr[-2000:])
    return json.loads(done.stdout.strip().splitlines()[-1])
