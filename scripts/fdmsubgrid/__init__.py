"""fdmsubgrid: the Python side of the fictitious-domain suspension simulator.

Write coupled cases and run them with fdmRun (case, which gathers foamcase: the OpenFOAM case folder,
deminput: the LIGGGHTS input, runner: the run, cli: the case scripts' shared options, cellpositions:
offsets in a mesh cell), the scenes several cases share (channelscenes: the sheared and the Poiseuille
channel; convergence: the mesh and box study; couettescene: the Couette suspension of Table 8), pack
spheres (packing), read what the runs write (output), compute the profiles of a wall-bounded suspension and its rheology (profiles,
rheology, timeseries), and the analysis of a sheared-suspension run folder (shear, the fdmProfiles
command) and of its contacts (contacts); the contact springs' stability theory and the resistances
they act against (contactstability: time-step limits, steady gaps, the spring recipe); squeeze flows
and the calibration of the solver's own resistance, the squeeze and the tangential wall functions (squeeze, calibration, wallcalibration),
and the measurement of the tangential pair modes (pairtangential); the probe of the pair's squeeze
stresslet (pairstresslet) and of its shear-mode stresslets (pairshearstresslet); the validation report
(validation).
./Allwmake installs the package (pip install -e scripts) so that a notebook can `import fdmsubgrid`;
the programs it runs are found through the environment (environment.program). docs/profiles.md.

    from fdmsubgrid import output, profiles, rheology
    snapshots, _ = output.record_snapshots("run/dem/particles.records")
"""
__version__ = "0.1.0"
