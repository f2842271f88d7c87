"""Closed-form motion: exact torque-free rotation, stability of the principal axes, the heavy top."""
