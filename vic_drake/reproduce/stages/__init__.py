"""The stages of the reproduction, one module each (see vic_drake.reproduce.pipeline).

Each module holds one stage function ``stage_<name>(ctx) -> value``, its
helpers and its constants.
"""
