"""Switch circuits in real ngspice (shared library, through PySpice).

The contact is a time-varying conductance driven from Python. SI units throughout.
"""
