"""A sample LeRobot SO-101 calibration, the shape ``lerobot-calibrate`` writes."""

from __future__ import annotations

#: Ranges chosen so that shoulder_pan (1267 ticks a side = 111.38 deg), shoulder_lift
#: (1186 ticks = 104.26 deg) and wrist_roll (full turn, 180 deg) pass the URDF's limits
#: (110, 100 and -157.2..162.8 deg) while elbow_flex (1085 = 95.38 deg) and wrist_flex
#: (1068 = 93.89 deg) stay inside (96.83 and 95.0 deg); elbow_flex is mounted reversed.
SAMPLE_CALIBRATION = {
    "shoulder_pan": {
        "id": 1,
        "drive_mode": 0,
        "homing_offset": -1470,
        "range_min": 758,
        "range_max": 3292,
    },
    "shoulder_lift": {
        "id": 2,
        "drive_mode": 0,
        "homing_offset": 157,
        "range_min": 812,
        "range_max": 3184,
    },
    "elbow_flex": {
        "id": 3,
        "drive_mode": 1,
        "homing_offset": 1105,
        "range_min": 910,
        "range_max": 3080,
    },
    "wrist_flex": {
        "id": 4,
        "drive_mode": 0,
        "homing_offset": -1750,
        "range_min": 980,
        "range_max": 3116,
    },
    "wrist_roll": {
        "id": 5,
        "drive_mode": 0,
        "homing_offset": 1354,
        "range_min": 0,
        "range_max": 4095,
    },
    "gripper": {
        "id": 6,
        "drive_mode": 0,
        "homing_offset": 1389,
        "range_min": 2034,
        "range_max": 3524,
    },
}
