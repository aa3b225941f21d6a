"""The Feetech STS3215's motion figures, and the limits lynxplan keeps its frames within.

LeRobot has no timing API: ``send_action`` writes one goal position per motor per frame and the
servo runs its own profile (LeRobot sets the servos' ``Acceleration`` register to 254), so a
frame asking for more than the servo can do makes the arm lag and then lurch. Frames from
:mod:`lynxplan.lerobot.export` and :mod:`lynxplan.lerobot.track` stay within a fraction of these
figures.

Figures (per motor, at the output shaft):

- No-load speed 0.222 s/60 deg = 45 rpm = 4.712 rad/s: the STS3215 datasheet figure at 12 V
  (STS3215-C018, 30 kg.cm, 1:345, the SO-101 follower's servo), as quoted beside measurements
  (about 46 rpm measured, +-2 %) in TheRobotStudio/SO-ARM100 issue #134. The 7.4 V version
  (C001) is quoted faster (0.192 s/60 deg = 52 rpm at 7.4 V, 0.238 s/60 deg at 6 V), so 45 rpm
  is the lower figure. Feetech's own PDF was not read here: an assumption, from that quote.
- Acceleration: the ``Acceleration`` register is address 41 (0x29), 1 byte, 0..254, in units of
  100 steps/s^2 ("set to 10: 1000 steps/s^2"), per the STS/ST3215 memory table (Feetech's, as
  reproduced with the python-st3215 driver, Mickael-Roger/python-st3215); address and size
  match lerobot 0.4.4's ``STS_SMS_SERIES_CONTROL_TABLE`` (``"Acceleration": (41, 1)``), and
  ``FeetechMotorsBus.configure_motors`` writes 254 there (and to ``Maximum_Acceleration``, 85)
  at every ``connect``. So 254 x 100 = 25,400 steps/s^2 = 25400 * 2 pi / 4096 = 38.96 rad/s^2,
  the servo's own profile cap. That the servo reaches it under an SO-101's load is an
  assumption (not measured here).
- Encoder: 4096 steps per turn (12 bits).

Under load the speed drops (the datasheet figure is no-load), hence the default fractions.
"""

from __future__ import annotations

import math

#: STS3215 no-load speed at 12 V, 45 rpm, in [rad/s] (see the module docstring).
STS3215_NO_LOAD_SPEED = 45.0 * 2.0 * math.pi / 60.0
#: The acceleration LeRobot leaves the servo's profile at (register 254 x 100 steps/s^2), in
#: [rad/s^2] (see the module docstring).
STS3215_PROFILE_ACCELERATION = 254 * 100 * 2.0 * math.pi / 4096
#: Fraction of those figures lynxplan's frames use by default: margin for load and supply
#: sag (a decision, not a datasheet figure).
DEFAULT_FRACTION = 0.5
#: Default joint speed bound of exported/tracked frames, in [rad/s] (2.36 rad/s, 135 deg/s).
DEFAULT_MAX_VELOCITY = DEFAULT_FRACTION * STS3215_NO_LOAD_SPEED
#: Default joint acceleration bound of exported frames, in [rad/s^2] (19.5 rad/s^2).
DEFAULT_MAX_ACCELERATION = DEFAULT_FRACTION * STS3215_PROFILE_ACCELERATION
#: LeRobot's usual control rate (``lerobot-record --dataset.fps`` default), in [frames/s].
DEFAULT_FPS = 30.0
