import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def cli():
    """Runs the bendlab executable with an argument vector (no shell); returns stdout."""
    exe = os.environ.get("BENDLAB_CLI")
    if not exe or not os.path.isfile(exe):
        pytest.skip("BENDLAB_CLI does not name the bendlab executable")

    def run(*args):
        done = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run
