import os
import pathlib

import pytest


@pytest.fixture
def source_dir() -> pathlib.Path:
    return pathlib.Path(os.environ.get("FLURRY_SOURCE_DIR") or pathlib.Path(__file__).parents[3])


@pytest.fixture
def dump_tool() -> str:
    """tests/dump_effect.cpp: the C++ API's results for an effect, passed by CTest."""
    path = os.environ.get("FLURRY_DUMP", "")
    if not path:
        pytest.skip("FLURRY_DUMP not set (CTest sets it to the flurry_py_dump helper)")
    return path
