"""Shared fixtures: where the real datasets are, and the rule for when they are missing.

Data comes from ``$VOLVIZ_DATA`` or ``../shared/data`` beside the repository. A test that needs it calls
``data_file("bluntfin/bluntfinxyz.bin")``: when the data is missing it skips with a clear reason, unless
``VOLVIZ_REQUIRE_DATA=1``, where a missing file is a failure.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def data_root() -> Path:
    env = os.environ.get("VOLVIZ_DATA")
    return Path(env).resolve() if env else (REPO.parent / "shared" / "data").resolve()


def data_file(relative: str) -> Path:
    """Path of a shared dataset; skip (or fail under VOLVIZ_REQUIRE_DATA=1) when it is missing."""
    path = data_root() / relative
    if not path.exists():
        message = f"dataset {relative} not found under {data_root()} (set VOLVIZ_DATA)"
        if os.environ.get("VOLVIZ_REQUIRE_DATA") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture
def data() -> "type[data_file]":
    """The ``data_file`` function as a fixture: ``data("headsq/quarter.1")``."""
    return data_file
