"""Figures (matplotlib) that explain the motion."""
