import os
import pathlib

import pytest


@pytest.fixture
def source_dir() -> pathlib.Path:
    return pathlib.Path(os.environ.get("FLURRY_SOURCE_DIR") or pathlib.Path(__file__).parents[3])


@pytest.fixture
def tool() -> str:
    """The flurry command-line tool (the C++ API's results), passed by CTest."""
    path = os.environ.get("FLURRY_TOOL", "")
    if not path:
        pytest.skip("FLURRY_TOOL not set (the flurry tool is built with FLURRY_SAMPLES)")
    return path
