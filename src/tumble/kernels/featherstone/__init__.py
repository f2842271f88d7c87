"""Compiled rigid-body algorithms for kinematic trees: RNEA, CRBA, ABA, energies, body poses.

Spatial vector algebra (Featherstone, *Rigid Body Dynamics Algorithms*,
Springer 2008, ch. 2), written with 3-vectors so that every quantity lives in
registers: a motion vector is ``(ω, v)`` (angular velocity, velocity of the
body point at the frame origin), a force vector ``(n, f)`` (moment about the
frame origin, force), both in body axes.

A robot is a kinematic tree in Featherstone's form (2008, §4.1.2): bodies
numbered so that every parent comes before its children, ``λ(i) < i``. It is
one float64 array ``P`` of shape (nb, :data:`PARAMS`), built once by
:class:`tumble.robot.RobotTree`; row ``i`` describes joint ``i`` and body
``i`` it moves, in *canonical* frames whose origin lies on the joint axis and
whose z axis is that axis. Its columns, and those of the algorithms' scratch
``W``, have names (:mod:`.layout`).

Motion of joint i: revolute ``R_J = Rz(θ)``; prismatic ``p_J = θ e_z``,
``θ = k q[c] + offset``, ``θ̇ = k q̇[c]``; the motion subspace ``S = (e_z, 0)``
or ``(0, e_z)``, so that ``S q̇`` and ``Sᵀ f`` are one component. A *floating
base* is body 0 with a free joint (:data:`FREE`) to the world: its configuration ``q[0:7] = (r, quat)``,
the origin of body 0 in the world frame (m) and the unit quaternion
``[w, x, y, z]`` of body 0 → world, its velocity ``q̇[0:6] = (ω, v)`` in body
0 axes; the joint coordinates follow, so the configuration index of
coordinate ``c`` is ``c + 1``. Gravity ``g`` is given in the world (base)
frame and enters as a base acceleration ``−g`` (Featherstone 2008, §5.3).

Mimic joints (several bodies on one coordinate) are constrained coordinates
``θ = G q + offset``: RNEA returns ``Gᵀ τ`` and CRBA ``Gᵀ M G``; the
articulated-body algorithm does not apply and :func:`forward_one` solves
``M q̈ = τ − h`` by Cholesky instead.

The single-sample functions ``*_one`` take a scratch array ``W`` (nb,
``WIDTH``), allocated once per chunk of a batch; ``*_batch`` run a batch in
parallel: ``prange`` over ``nc`` chunks of consecutive samples. The
single-state entries :func:`rnea`, :func:`crba`, :func:`aba` take their
scratch as one flat :func:`workspace` kept by the model and allocate nothing.

One module per job: :mod:`.layout` (the columns, the scratch), :mod:`.spatial`
(the spatial algebra on a row), :mod:`.inverse` (RNEA, CRBA), :mod:`.forward`
(ABA, and CRBA with Cholesky for mimic joints), :mod:`.kinematics` (poses,
energies, centroidal momentum).
"""

from tumble.kernels.featherstone.forward import (aba, aba_batch, aba_one, cholesky_solve, fd_scratch, fd_views,
                                                 forward_one, mimic)
from tumble.kernels.featherstone.inverse import crba, crba_batch, crba_one, rnea, rnea_batch, rnea_one
from tumble.kernels.featherstone.kinematics import (body_poses_batch, centroidal_momentum_batch,
                                                    centroidal_momentum_one, energy_batch, energy_one, poses_batch,
                                                    poses_one, world_poses)
from tumble.kernels.featherstone.layout import (COORDINATE, FREE, MULTIPLIER, PARAMS, PARENT, PRISMATIC, REVOLUTE,
                                                floating, scratch, state_copy, state_offset, workspace,
                                                workspace_size)

__all__ = ["COORDINATE", "FREE", "MULTIPLIER", "PARAMS", "PARENT", "PRISMATIC", "REVOLUTE", "aba", "aba_batch",
           "aba_one", "body_poses_batch", "centroidal_momentum_batch", "centroidal_momentum_one", "cholesky_solve",
           "crba", "crba_batch", "crba_one", "energy_batch", "energy_one", "fd_scratch", "fd_views", "floating",
           "forward_one", "mimic", "poses_batch", "poses_one", "rnea", "rnea_batch", "rnea_one", "scratch",
           "state_copy", "state_offset", "workspace", "workspace_size", "world_poses"]
