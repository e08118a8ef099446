"""Shared test set-up: the problem builders in this folder are importable from every sub-folder."""

import signal
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

# Property tests draw the same examples on every run and in every clone (CI is deterministic
# and no failing example is stored in a database to replay): `--hypothesis-profile=explore`
# searches with fresh random examples instead.
from hypothesis import settings  # noqa: E402

settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("deterministic")


@pytest.fixture
def no_blocking():
    """Fail (instead of hanging) if the code blocks on a named pipe for 60 s."""

    def blocked(signum, frame):
        raise AssertionError("blocked on a named pipe")

    previous = signal.signal(signal.SIGALRM, blocked)
    signal.alarm(60)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)
