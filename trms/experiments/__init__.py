"""The thesis's experiments as functions of a plant, with their tables beside the printed values.

Each experiment runs on any :class:`trms.plant.Plant`, so the same code fills the "linear model"
and the "twin" columns of the report (:mod:`trms.report`); the two worlds are built by :mod:`trms.worlds`
and the tables, figures and sections drawn by :mod:`trms.present`.

ch3_identification  ch. 3 run on a plant: 1-DOF and 2-DOF identification (spectra, coherence, ARMAX, residual tests,
                    validation, the identified models' modes)
ch3_tables          ch. 3 presented: the 1-DOF table and Table 3.1, over the twin's seeds
ch4_shaping         ch. 4 run on a plant: the doublets of Tables 4.2 and 4.3, ZV/ZVD shapers, the ambient floor
ch4_tables          ch. 4 presented: Tables 4.2 and 4.3 with their checked notes, over the twin's seeds
ch5_narx            ch. 5: NARX-RBF against ARMAX (Table 5.1) and the u1 -> yaw RBF of the future work
ch67_lqg            ch. 6/7 run on a plant: SAS and CSAS cases, push rejection, loop margins
ch67_tables         ch. 6/7 presented: Table 6.1, the rig's cases, the push, the margins
ch67_amplitudes     R = 1 flown at several command amplitudes on the twin and on its linearisation
ch67_chapter        the ch. 6/7 section assembled over the twin's seeds (findings, explanations, figures)
ch7_findings        ch. 7's findings (what the rig showed) tested on each world, with their measured explanations
ch7_side_mode       the ch. 7 low-pass finding on the twin's linearisation without and with the thesis's 0.25 Hz mode
ch8                 ch. 8's future work (:mod:`trms.experiments.ch8`): the 2-DOF autopilot, fault tolerance, LQG,
                    PID, MPC and H-infinity side by side on the twin, and robustness over its parameter spread
lqg_design          one integral LQG design as data (``trms design``)
single_runs         one pitch loop or one 2-DOF autopilot run on a plant (``trms run``)
task_baselines      the LQG baselines of the control tasks (:mod:`trms.envs`)
"""

from trms.experiments.ch4_tables import table_4_2, table_4_3
from trms.experiments.ch67_tables import table_6_1

__all__ = ["table_4_2", "table_4_3", "table_6_1"]
