"""Ctrl-C stops a render: SIGINT one second into a render that would take a
minute raises KeyboardInterrupt within seconds (a call into Rust that never
looks for signals would raise only when the render ends). Run in a child
process, so the signal reaches nothing else."""

import json
import subprocess
import sys
from pathlib import Path

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "examples" / "sphere.toml"

SCRIPT = r"""
import json, os, signal, sys, threading, time
import polar_sfp as ps
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.perf_counter()
try:
    ps.render(sys.argv[1], spp=16384, size=256)
    outcome = "finished"
except KeyboardInterrupt:
    outcome = "interrupted"
print(json.dumps({"outcome": outcome, "seconds": time.perf_counter() - start}))
"""


def test_ctrl_c_stops_a_render():
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(SCENE)],
                          capture_output=True, text=True, timeout=600, check=True)
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    print(figures)
    assert figures["outcome"] == "interrupted", figures
    assert figures["seconds"] < 10, figures
