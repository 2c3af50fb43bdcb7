"""
The equivalent wall, frame and arch
===================================

Paper [003] reduces a rocking wall, a symmetric frame and a masonry arch to the rocking
parameters of a block. Here each structure is rocked through the same sine pulses by its full
mechanism, eq. (8) of [003], and by its equivalent block, and the peak rotations are compared.
The frame's equivalence is exact (Table I of [003], with its own restitution); the wall's
and the arch's are approximations.
"""

import matplotlib.pyplot as plt
import numpy as np

import rockstudy as rs
from rockstudy.structures import Arch, RockingWall, SymmetricFrame

structures = {
    "rocking wall": RockingWall(half_diagonal=1.0, slenderness=0.1, restitution=0.9),
    "symmetric frame": SymmetricFrame(half_diagonal=1.0, slenderness=0.1, mass_ratio=0.5),
    "arch (t/r = 0.15)": Arch(inclusion_angle=np.pi, thickness=0.75, radius=5.0,
                              restitution=0.9),
}
ratios = np.linspace(1.2, 4.0, 12)  # pulse amplitude / uplift acceleration of the structure

fig, axes = plt.subplots(1, 3, figsize=(11, 3.6))
for ax, (name, structure) in zip(axes, structures.items()):
    params = structure.rocking_parameters()
    if isinstance(params, tuple):
        params = params[0]
    uplift = params.uplift * 9.81  # lambda g: the uplift acceleration [m/s^2]
    period = 2 * np.pi / (2.0 * params.frequency_parameter)
    block = structure.equivalent_block()
    mech, equiv = [], []
    for r in ratios:
        pulse = rs.motions.SinePulse(amplitude=r * uplift, period=period)
        m = rs.simulate(structure, pulse)
        b = rs.simulate(block, pulse)
        # the mechanism reports its own coordinate phi, the block theta = phi / kappa: each is
        # drawn over its own critical rotation (phi_cr, and theta_cr = phi_cr / kappa)
        mech.append(np.nan if m.overturned else m.max_rotation / params.critical_rotation)
        equiv.append(np.nan if b.overturned else b.max_rotation / block.slenderness)
    ax.plot(ratios, mech, "o-", label="mechanism, eq. (8)")
    ax.plot(ratios, equiv, "s--", label="equivalent block")
    ax.set_title(name)
    ax.set_xlabel("pulse amplitude / uplift acceleration")
axes[0].set_ylabel("peak rotation / critical rotation\n(gaps: overturned)")
axes[0].legend()
fig.tight_layout()
