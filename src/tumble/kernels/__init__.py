"""Compiled models, one file per model: a :class:`typing.NamedTuple` of parameters and its protocol overloads.

Each module defines the kernel of one model (the right-hand side, projection
and state size of :mod:`tumble._protocol`, and the capabilities it provides
to the methods) below the integration engine, which imports none of them.
The user-level models (:class:`tumble.simulate.Model`) build their kernels
from these modules.
"""
