"""Run test code in a fresh interpreter with numba's JIT disabled, i.e. the compiled
kernels' plain Python source (the readable reference the compiled steps are held to)."""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def interpreted_json(code: str):
    """The JSON that code prints, run without numba's JIT from the repository root."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, check=True)
    return json.loads(out.stdout)
