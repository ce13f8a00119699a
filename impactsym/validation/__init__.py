"""The models against the crashes the field validates on (the seed's Tables 5-8).

Every dataset of ``impactsym/data/validation/`` (shipped in the wheel; sources,
units and known defects in its ``README.md``) runs through every model its data
allow, through the public API (:func:`impactsym.crash3`, :func:`impactsym.solve`)
with programmatic scenes:

- **RICSAC** (12 staged car-to-car crashes, Calspan 1978): CRASH3 delta-V of all
  24 vehicles from their crush profiles, as published and with Neades' profile
  adjustments, against the three published versions of the measured delta-V;
  CRASH3 energies against Woolley's CRASH3, Brach's PIM fit and the measured
  loss; the rigid impulse-momentum model (Brach's fitted e, μ = μ_c) with the
  impact centre approximated from the damage centre and the class dimensions,
  with its sensitivity to that approximation;
- **IIHS small-overlap barrier tests** (41, Brach et al. SAE 2014-01-0469): the
  rigid model with Brach's fitted parameters against the measured delta-V and
  yaw-rate change;
- **IIHS small-overlap vehicle-to-vehicle tests** (9 tests, 18 vehicles, same
  paper): the rigid model with Brach's fitted e, μ, φ, Γ, the CG-to-impact
  distance APPROXIMATED from his barrier fits of the same car model and the
  masses ASSUMED (the Fusion's), against the measured |delta-V| and yaw-rate
  change, with the sensitivity to d, the mass ratio and k;
- **RICSAC rest positions** (RICSAC 2, 3, 6, 10; Day, SAE 2004-01-1207, Table 7):
  the run-out forward from Vossou's measured separation velocities with every
  wheel ASSUMED rolling (and locked, as a bracket), and the separation state
  fitted to the measured rest pose against the measured one; SIMON's and
  EDSMAC4's published rest positions beside; separation poses read from the
  paper's figures;
- **NHTSA 4364, 4438, 4474** (car-to-SUV, Rose et al. SAE 2006-01-0908): the
  rigid model with the published inputs against the published PIM energies,
  delta-V and yaw rates, and the measured delta-V.

Errors are percent of the reference: 100·(model − reference)/reference. The
statistics per comparison are the number of rows, the median and worst |error|
and the median signed error (bias). Every assumption is stated in ``ASSUMPTIONS``
and in the tables' notes; nothing is tuned to the measurements.

The rooms: ``common`` (data folder, reader, Comparison, statistics), one loader
module per source (``ricsac``, ``runout``, ``iihs``, ``nhtsa``), ``report`` (the table of
comparisons run on them), ``figures`` and ``markdown`` (output).
"""

from .common import DATA_DIR, Comparison, Dataset, stats
from .figures import plot
from .iihs import iihs_barrier, iihs_v2v, v2v_oblique_readings, v2v_sensitivity
from .markdown import markdown, statistics_rows, text_summary
from .nhtsa import nhtsa
from .report import ASSUMPTIONS, COMPARISONS, report
from .ricsac import ricsac_crash3, ricsac_energy, ricsac_momentum, ricsac_pim
from .runout import ricsac_runout_fit, ricsac_runout_forward, ricsac_runout_table

__all__ = [
    "ASSUMPTIONS",
    "COMPARISONS",
    "DATA_DIR",
    "Comparison",
    "Dataset",
    "iihs_barrier",
    "iihs_v2v",
    "markdown",
    "nhtsa",
    "plot",
    "report",
    "ricsac_crash3",
    "ricsac_energy",
    "ricsac_momentum",
    "ricsac_pim",
    "ricsac_runout_fit",
    "ricsac_runout_forward",
    "ricsac_runout_table",
    "statistics_rows",
    "stats",
    "text_summary",
    "v2v_oblique_readings",
    "v2v_sensitivity",
]
