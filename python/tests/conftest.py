import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import skybake


@pytest.fixture(scope="session")
def cli():
    """The skybake command-line tool of the same build (ctest sets SKYBAKE_CLI)."""
    path = os.environ.get("SKYBAKE_CLI") or shutil.which("skybake")
    if not path:
        pytest.skip("the skybake CLI is not known (set SKYBAKE_CLI)")

    def run(*args):
        r = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError(f"skybake {' '.join(map(str, args))} failed: {r.stderr}")
        return r

    return run


@pytest.fixture(scope="session")
def bowl():
    return skybake.generate_mesh("bowl", 4000)


@pytest.fixture(scope="session")
def sphere():
    return skybake.generate_mesh("sphere", 2000)


@pytest.fixture
def tmp(tmp_path: pathlib.Path):
    return tmp_path


def rng():
    return np.random.default_rng(12345)
