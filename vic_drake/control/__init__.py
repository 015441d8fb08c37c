"""Online control math: energy tank, stiffness QP, force references, replay.

Pure functions and dataclasses (no Drake systems here; see
``vic_drake.systems`` for the LeafSystems that wrap them).
"""
