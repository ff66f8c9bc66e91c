"""Codels of the ATRV rover's functional modules (seed 004 §4.1.1): RFLEX, SICK, NDD, PLATINE,
CAMERA and ANTENNA. Each reaches the simulated devices through `sdi.hardware` and falls back on
a trivial model of its own when no simulator is attached."""

# The ATRV's footprint, as system.spec's body block gives it to the simulator: the codels that
# need the robot's size (SICK's mount, NDD's clearances) know it as the real robot's codels do.
LENGTH, WIDTH = 1.05, 0.65  # m
