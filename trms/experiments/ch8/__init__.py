"""Chapter 8's future work on the twin, each a function of a plant like the thesis's experiments.

designs             every controller's design on eq. (3.11), damping the 0.34 Hz mode: the one builder of the loops
controllers         LQG, PID, MPC and H-infinity flown side by side on the 1-DOF pitch (``trms compare-controllers``)
controllers_mimo    the same on the 2-DOF rig
comparison          the comparison's tables, figure and files
sweep               the designs' amplitude sweep on the twin, with and without the thrust-curve inversion
spread              every design over the twin's parameter spread: Monte Carlo success and robust stability
robustness          the LQG loops' Monte Carlo over the twin's physical parameters and its files (``trms robustness``)
autopilot           a 2-DOF LQG autopilot against two SISO loops, its targets and scenarios
autopilot_margins   the autopilot's margins at each plant input
autopilot_tuning    how the autopilot's weights were chosen (a search flown on the twin)
autopilot_section   the autopilot's tables and figures
fault_tolerance     faults in the twin, their detection and the LQG's reconfiguration (1-DOF)
fault_tolerance_2dof the same for the 2-DOF autopilot when the tail rotor sticks
"""
