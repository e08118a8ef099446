"""Shared test set-up: the problem builders in this folder are importable from every sub-folder."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

# Property tests draw the same examples on every run and in every clone (CI is deterministic
# and no failing example is stored in a database to replay): `--hypothesis-profile=explore`
# searches with fresh random examples instead.
from hypothesis import settings  # noqa: E402

settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("deterministic")
