"""What the tests share: the repository, and the command line built from it (the Python runs
are compared with its runs bit for bit)."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `signorini` binary: $SIGNORINI_CLI, else the repository's debug build."""
    path = Path(os.environ.get("SIGNORINI_CLI", REPO / "target" / "debug" / "signorini"))
    if not path.is_file():
        pytest.fail(f"no command line at {path}: build it (cargo build) or set SIGNORINI_CLI")
    return path


@pytest.fixture
def run_cli(cli, tmp_path):
    """Runs the command line in the repository; returns (exit code, stdout, stderr)."""

    def run(*args):
        p = subprocess.run([str(cli), *map(str, args)], cwd=REPO, capture_output=True, text=True)
        return p.returncode, p.stdout, p.stderr

    return run
