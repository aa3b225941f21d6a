"""A sample LeRobot SO-101 calibration (the shape ``lerobot-calibrate`` writes) and the models."""

from __future__ import annotations

import json
import warnings

import pytest

import lynxplan
from lynxplan.lerobot.calibration import load_calibrated
from tests.lerobot.sample import SAMPLE_CALIBRATION


@pytest.fixture
def calibration_file(tmp_path):
    path = tmp_path / "my_follower.json"
    path.write_text(json.dumps(SAMPLE_CALIBRATION, indent=4))
    return path


@pytest.fixture(scope="session")
def so101():
    return lynxplan.load_robot("so101")


@pytest.fixture(scope="session")
def so101_calibrated(tmp_path_factory):
    path = tmp_path_factory.mktemp("cal") / "my_follower.json"
    path.write_text(json.dumps(SAMPLE_CALIBRATION))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_calibrated("so101", path)
