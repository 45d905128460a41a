# Paths the suite needs, set by ctest (test/CMakeLists.txt): the riner CLI, ../shared.
import os
import pathlib

import pytest


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("RINER_CLI", "")
    if not path or not os.path.exists(path):
        pytest.skip("RINER_CLI not set (run through ctest)")
    return path


@pytest.fixture(scope="session")
def shared():
    path = pathlib.Path(os.environ.get("RINER_SHARED_DIR", "../shared"))
    if not (path / "data").is_dir():
        pytest.skip("../shared/data not found")
    return path / "data"
