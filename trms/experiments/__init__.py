"""The thesis's experiments as functions of a plant, with their tables beside the printed values.

Each experiment runs on any :class:`trms.plant.Plant`, so the same code fills the "linear model"
and the "twin" columns of the report (:mod:`trms.report`).

plants              the two worlds: ``make_plant(world, config)`` and the controllers' design models
identification_ch3  ch. 3: 1-DOF and 2-DOF identification (spectra, coherence, ARMAX, residual tests, validation)
shaping_tables      ch. 4: Tables 4.2 and 4.3 (doublet shaping) and ZV/ZVD input shapers
narx_ch5            ch. 5: NARX-RBF against ARMAX (Table 5.1) and the u1 -> yaw RBF of the future work
lqg_cases           ch. 6/7 run on a plant: SAS and CSAS cases, push rejection, loop margins
lqg_tables          ch. 6/7 presented: Table 6.1, the rig's cases, the push, the margins, the ch. 7 findings
side_mode           the ch. 7 low-pass finding on the twin's linearisation without and with the thesis's 0.25 Hz mode
mimo_lqg_ch8        ch. 8: a 2-DOF LQG autopilot against two SISO loops
robustness          closed loops under a seeded spread of the twin's physical parameters
robustness_study    the robustness Monte Carlo as files (JSON, histograms, worst-case Records): `trms robustness`
figures, section, tables   figures, report sections and side-by-side tables
"""

from trms.experiments.ch4_shaping import table_4_2, table_4_3
from trms.experiments.ch67_tables import table_6_1
from trms.present.sections import FigureRef, Section
from trms.present.tables import ComparisonTable, side_by_side
from trms.worlds import design_model, make_plant

__all__ = [
    "ComparisonTable",
    "FigureRef",
    "Section",
    "design_model",
    "make_plant",
    "side_by_side",
    "table_4_2",
    "table_4_3",
    "table_6_1",
]
