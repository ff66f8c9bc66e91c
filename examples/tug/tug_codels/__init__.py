"""Codels of the warehouse tug's modules (DRIVE, LIFT, SCANNER): the only Python the tug needs."""
