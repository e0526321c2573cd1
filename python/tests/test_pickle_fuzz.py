"""No pickle takes the interpreter down: 10,000 mutated pickles and states of a model and
its parts (tests/fuzz_pickle_states.py) in a child process, seeded, where a crash fails
the test; what loads is then used, edited (add_point3D, delete_observation, ...) and
written."""

import json
import os
import pathlib
import subprocess
import sys


def test_mutated_pickles_and_states_never_crash(tmp_path):
    child = pathlib.Path(__file__).with_name("fuzz_pickle_states.py")
    result = subprocess.run([sys.executable, child, "59", "10000", tmp_path], timeout=300,
                            capture_output=True, text=True, env=dict(os.environ))
    assert result.returncode == 0, (
        f"the fuzz child ended with {result.returncode} (a negative number is the signal "
        f"that killed it):\n{result.stderr[-3000:]}")
    counts = json.loads(result.stdout.strip().splitlines()[-1])
    # Each kind of outcome happened: the test reaches the checks and the calls.
    assert counts["refused"] > 1000 and counts["loaded"] > 100 and counts["written"] > 50, counts
    assert counts["edited"] > 20, counts  # the model's edits succeeded, not only refused
