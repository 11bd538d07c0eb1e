"""Writing and running coupled cases (OpenFOAM fluid/ + LIGGGHTS dem/), see docs/cases.md.

The names of the modules that do each job, gathered in one namespace for the case scripts
(`from fdmsubgrid import case`; case.write_fluid_case, case.write_dem_input, case.run, ...):

  foamcase       the OpenFOAM case folder fdmFoam reads (Box, write_fluid_case, write_initial_velocity)
  deminput       the LIGGGHTS input fdmDEM reads (write_dem_input, subgrid_pair_style, held_step_runs,
                 records_line, uncalibrated, refusal, scene_calibration: the calibration table a scene runs
                 with, interpolated blocks written into its dem/ where their measured error allows)
  runner         running it with fdmRun and reading what it recorded (run, run_and_read, read_held_steps,
                 delete_fields; how a run ended: last_error, records_finite)
  cli            the command-line options the case scripts share (add_run_options, boxes_and_offsets,
                 add_size_options, size_distribution)
  cellpositions  the offsets of a sphere in its mesh cell (halton_points, symmetric_cell_offsets)
"""
from .cellpositions import halton_points, symmetric_cell_offsets
from .cli import add_run_options, add_size_options, boxes_and_offsets, size_distribution
from .deminput import (RECORD_EVERY_STEP, SceneCalibration, UncalibratedScene, balancing_force_line, held_step_runs,
                       records_line, refusal,
                       scene_calibration, subgrid_pair_style, uncalibrated, write_dem_input)
from .foamcase import (DEFAULT_LINEAR_SOLVER, HEADER, LINEAR_SOLVERS, Box, foam_file, foam_vector,
                       write_control_dict, write_fluid_case, write_initial_velocity)
from .runner import delete_fields, last_error, read_held_steps, records_finite, run, run_and_read

__all__ = ["Box", "DEFAULT_LINEAR_SOLVER", "HEADER", "LINEAR_SOLVERS", "RECORD_EVERY_STEP", "add_run_options",
           "balancing_force_line",
           "add_size_options", "size_distribution",
           "boxes_and_offsets", "delete_fields", "foam_file", "foam_vector", "halton_points", "held_step_runs",
           "last_error", "read_held_steps", "records_finite", "records_line", "refusal", "run", "run_and_read", "SceneCalibration", "scene_calibration",
           "subgrid_pair_style", "UncalibratedScene",
           "symmetric_cell_offsets", "uncalibrated", "write_control_dict", "write_dem_input", "write_fluid_case",
           "write_initial_velocity"]
