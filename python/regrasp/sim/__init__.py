"""Simulation through Python: the quasi-static simulator (``quasistatic``) and the validation of
motion cones against simulators (``validation``)."""
