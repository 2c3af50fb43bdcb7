"""Write the synthetic site hazard curves of the museum example (run from the repo root).

The site is made up, not a real one: a mean PGA hazard curve of the second-order form of
Vamvatsikos (2013), ln lambda = c0 - k1 ln x - k2 ln^2 x (x in g), whose three constants are
chosen so that the curve passes through three return periods of a moderately active site:
0.05 g at 30 years, 0.25 g at 475 years and 0.5 g at 2,475 years. It is tabulated on 25
levels from 0.01 g to 2 g and written twice:

- ``site_pga.csv``: two columns, level [g] and mean annual rate of exceedance [1/yr];
- ``site_pga_openquake.csv``: the same curve as OpenQuake exports a classical hazard curve,
  probabilities of exceedance in an investigation time of 50 years, poe = 1 - exp(-50 lambda).
"""

from pathlib import Path

import numpy as np

ANCHORS = ((0.05, 1 / 30), (0.25, 1 / 475), (0.5, 1 / 2475))  # (PGA [g], annual rate)
LEVELS = np.geomspace(0.01, 2.0, 25)
YEARS = 50.0


def constants():
    """(c0, k1, k2) of ln lambda = c0 - k1 L - k2 L^2 through the three anchors."""
    L = np.log([a[0] for a in ANCHORS])
    A = np.column_stack([np.ones(3), -L, -(L**2)])
    return np.linalg.solve(A, np.log([a[1] for a in ANCHORS]))


def main(out=Path(__file__).parent):
    c0, k1, k2 = constants()
    L = np.log(LEVELS)
    rates = np.exp(c0 - k1 * L - k2 * L**2)
    head = f"# synthetic site (data/hazard/make_site_pga.py): c0={c0:.6f} k1={k1:.6f} k2={k2:.6f}"
    rows = "\n".join(f"{x:.7f},{r:.6e}" for x, r in zip(LEVELS, rates, strict=True))
    (out / "site_pga.csv").write_text(f"{head}\npga_g,annual_rate\n{rows}\n")
    poe = -np.expm1(-YEARS * rates)
    meta = f"#,,,,\"kind='mean', investigation_time={YEARS:.1f}, imt='PGA'\""
    cols = ",".join(f"poe-{x:.7f}" for x in LEVELS)
    vals = ",".join(f"{p:.6E}" for p in poe)
    (out / "site_pga_openquake.csv").write_text(
        f"{meta}\nlon,lat,depth,{cols}\n0.00000,0.00000,0.00000,{vals}\n"
    )
    return c0, k1, k2


if __name__ == "__main__":
    print(main())
