"""The names of the reproduce pipeline's stages, in run order.

:data:`vic_drake.reproduce.pipeline.STAGES` pairs each with its function
(tests/reproduce/test_options.py checks that the two agree); the names live
here, in a module that imports nothing, so that the options and the command
line's help can name the stages without importing the pipeline.
"""

STAGE_NAMES = (
    "offline_real",
    "offline_sim",
    "map",
    "real_scans",
    "scans",
    "replay",
    "compare_real",
    "online",
    "claims",
    "report",
)
