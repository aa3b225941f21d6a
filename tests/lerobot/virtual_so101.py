"""LeRobot's own ``SOFollower`` on six virtual STS3215 servos, driven over stdin/stdout.

Run by a Python that has ``lerobot`` (0.4.x) and ``feetech-servo-sdk`` (not lynxplan's: it imports
nothing from lynxplan)::

    python virtual_so101.py CALIBRATION_DIR ROBOT_ID USE_DEGREES START_TICKS_JSON

Only the serial port is replaced: ``scservo_sdk.PortHandler`` becomes :class:`VirtualServoPort`,
which answers Feetech protocol-0 packets (ping, read, write, sync read, sync write) from a
register table per servo (STS3215 model number 777, the calibration's homing offset and limits
preloaded, ``Present_Position`` at ``START_TICKS``). Everything above it is LeRobot's code:
``SOFollower.connect`` (handshake, calibration check, ``configure``), ``get_observation``
(sync read, normalisation) and ``send_action`` (unnormalisation, sync write of
``Goal_Position``). Each servo follows its goal at once (``Present_Position`` = goal).

Commands, one JSON object per stdin line, one JSON answer per stdout line:
``{"op": "connected"}``, ``{"op": "observe"}``, ``{"op": "send", "action": {...}}``,
``{"op": "goals"}`` (every ``Goal_Position`` sync write: a list of ``{id: ticks}``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import ClassVar

import scservo_sdk as scs

MODEL_NUMBER = 777  # STS3215 (lerobot.motors.feetech.tables.MODEL_NUMBER_TABLE)
GOAL_POSITION, PRESENT_POSITION = 42, 56
HOMING_OFFSET, MIN_LIMIT, MAX_LIMIT = 31, 9, 11
GOALS: list[dict[int, int]] = []


def _status(servo: int, data: bytes = b"") -> bytes:
    body = bytes([servo, len(data) + 2, 0]) + data
    return b"\xff\xff" + body + bytes([~sum(body) & 0xFF])


class VirtualServoPort(scs.PortHandler):  # type: ignore[misc]
    """The serial port with six STS3215 behind it (registers per id, little-endian words)."""

    memory: ClassVar[dict[int, bytearray]] = {}

    def __init__(self, port_name: str) -> None:
        super().__init__(port_name)
        self.pending = bytearray()

    def openPort(self) -> bool:
        self.is_open = True
        return True

    def closePort(self) -> None:
        self.is_open = False

    def clearPort(self) -> None:
        pass

    def setBaudRate(self, baudrate: int) -> bool:
        self.baudrate = baudrate
        self.tx_time_per_byte = (1000.0 / baudrate) * 10.0
        return True

    def getBytesAvailable(self) -> int:
        return len(self.pending)

    def readPort(self, length: int) -> bytes:
        out, self.pending = bytes(self.pending[:length]), self.pending[length:]
        return out

    def writePort(self, packet: list[int]) -> int:
        servo, length, instruction = packet[2], packet[3], packet[4]
        params = bytes(packet[5 : 3 + length])
        if instruction == scs.INST_PING and servo in self.memory:
            self.pending += _status(servo)
        elif instruction == scs.INST_READ and servo in self.memory:
            address, size = params[0], params[1]
            self.pending += _status(servo, bytes(self.memory[servo][address : address + size]))
        elif instruction == scs.INST_WRITE and servo in self.memory:
            self._store(servo, params[0], params[1:])
            self.pending += _status(servo)
        elif instruction == scs.INST_SYNC_READ:
            address, size = params[0], params[1]
            for i in params[2:]:
                self.pending += _status(i, bytes(self.memory[i][address : address + size]))
        elif instruction == scs.INST_SYNC_WRITE:
            address, size = params[0], params[1]
            rows = [params[k : k + 1 + size] for k in range(2, len(params), 1 + size)]
            for row in rows:
                self._store(row[0], address, row[1:])
            if address == GOAL_POSITION:
                GOALS.append({row[0]: row[1] | (row[2] << 8) for row in rows})
        return len(packet)

    def _store(self, servo: int, address: int, data: bytes) -> None:
        self.memory[servo][address : address + len(data)] = data
        if address == GOAL_POSITION:  # an ideal servo: at its goal at once
            self.memory[servo][PRESENT_POSITION : PRESENT_POSITION + 2] = data[:2]


def _word(value: int, sign_bit: int | None = None) -> bytes:
    if sign_bit is not None and value < 0:
        value = -value | (1 << sign_bit)
    return bytes([value & 0xFF, value >> 8])


def servos(calibration: dict[str, dict[str, int]], start: dict[str, int]) -> dict[int, bytearray]:
    memory = {}
    for name, c in calibration.items():
        table = bytearray(128)
        table[3:5] = _word(MODEL_NUMBER)
        table[0], table[1] = 3, 10  # firmware 3.10
        table[HOMING_OFFSET : HOMING_OFFSET + 2] = _word(c["homing_offset"], 11)
        table[MIN_LIMIT : MIN_LIMIT + 2] = _word(c["range_min"])
        table[MAX_LIMIT : MAX_LIMIT + 2] = _word(c["range_max"])
        table[PRESENT_POSITION : PRESENT_POSITION + 2] = _word(start[name])
        memory[c["id"]] = table
    return memory


def main() -> None:
    folder, robot_id, degrees, start = sys.argv[1], sys.argv[2], sys.argv[3] == "1", sys.argv[4]
    calibration = json.loads((Path(folder) / f"{robot_id}.json").read_text())
    VirtualServoPort.memory = servos(calibration, json.loads(start))
    scs.PortHandler = VirtualServoPort
    from importlib import metadata

    from lerobot.robots.so_follower import SO101FollowerConfig, SOFollower

    config = SO101FollowerConfig(
        port="/dev/virtual-so101", id=robot_id, calibration_dir=Path(folder), use_degrees=degrees
    )
    robot = SOFollower(config)
    robot.connect()  # LeRobot's handshake, calibration check and configure, on the virtual bus
    print(json.dumps({"lerobot": metadata.version("lerobot")}), flush=True)
    for line in sys.stdin:
        command = json.loads(line)
        if command["op"] == "connected":
            answer: object = robot.is_connected
        elif command["op"] == "observe":
            answer = robot.get_observation()
        elif command["op"] == "send":
            answer = robot.send_action(command["action"])
        else:
            answer = [{str(k): v for k, v in goal.items()} for goal in GOALS]
        print(json.dumps(answer), flush=True)
    robot.disconnect()


if __name__ == "__main__":
    main()
