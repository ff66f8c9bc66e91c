"""Codels of the ATRV rover's functional modules (seed 004 §4.1.1): RFLEX, SICK, NDD, PLATINE,
CAMERA and ANTENNA. Each reaches the simulated devices through `sdi.hardware` and falls back on
a trivial model of its own when no simulator is attached."""
