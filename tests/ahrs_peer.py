"""The `ahrs` package's Madgwick, Mahony and EKF run on tumble's data: the one place where its frames are converted.

tumble's AHRS filters estimate ``q`` (scalar first) mapping body axes to the level frame L = north–west–up:
the accelerometer at rest reads ``R(q)ᵀ [0, 0, 1]`` and the field's horizontal part lies along ``+x_L``.
`ahrs` (0.4) also uses scalar-first quaternions mapping the sensor frame to its Earth frame (its
``q̇ = ½ q ⊗ [0, ω]``, its expected readings ``R(q)ᵀ d``) and reads the accelerometer as ``+z`` at rest in all
three filters, but places the field differently:

* ``Madgwick``: horizontal field along ``+x`` (``b = [0, b_x, 0, b_z]``) — L itself;
* ``Mahony``: horizontal field along ``+y`` (``[0, |h_xy|, h_z]``) — L turned by +90° about z (east–north–up),
  so ``q_L = q_z(−90°) ⊗ q_ahrs``;
* ``EKF`` (frame="NED", reference ``a_ref = [0, 0, 1]``): the field ``magnetic_ref`` given as a vector, here
  L's ``[cos δ, 0, −sin δ]`` — L itself.
"""

import numpy as np

from tumble import attitude

#: q_{L ← peer frame} of each peer filter.
PEER_FRAME = {
    "madgwick": attitude.identity(),
    "mahony": attitude.from_rotvec([0.0, 0.0, -np.pi / 2]),
    "ekf": attitude.identity(),
}


def run_peer(name: str, rate, accel, mag, dt: float, q0, **options) -> np.ndarray:
    """The `ahrs` filter ``name`` over K samples (tumble's sample convention: q[0] = q0, rate[0] unused),
    its attitudes converted to body → L (K, 4)."""
    from ahrs.filters import EKF, Madgwick, Mahony

    to_peer = attitude.conjugate(PEER_FRAME[name])
    if name == "madgwick":
        filt, update = Madgwick(Dt=dt, **options), "updateMARG"
    elif name == "mahony":
        filt, update = Mahony(Dt=dt, **options), "updateMARG"
    else:
        delta = options.pop("inclination")
        # its measurement model reads the field only when the filter was built with magnetometer data
        filt = EKF(mag=np.asarray(mag), frequency=1.0 / dt, frame="NED",
                   magnetic_ref=np.array([np.cos(delta), 0.0, -np.sin(delta)]), **options)
        update = "update"
    step = getattr(filt, update)
    q = np.empty((len(rate), 4))
    q[0] = attitude.multiply(to_peer, q0)
    for k in range(1, len(rate)):
        q[k] = step(q[k - 1], gyr=rate[k], acc=accel[k], mag=mag[k], dt=dt)
    return attitude.multiply(PEER_FRAME[name], q)
