"""pliant: how soft an object is, from tracked particle trajectories.

The names below come from the extension module ``pliant._pliant`` (C++, pybind11); see
docs/python.md for the contracts (array shapes, units, frames, errors, threads).

Recordings
    Recording, read_recording, make_recording, write_recording
The command line's jobs (same options, same output, same messages)
    estimate, diagnose, refine, simulate
On the controller's objects, stepped with NumPy arrays
    OnlineEstimator, GraspGuard
Errors and warnings
    PliantError(RuntimeError), UsageError(PliantError, ValueError),
    InputError(PliantError, ValueError), PliantWarning(UserWarning)
"""

from ._pliant import (
    GraspGuard,
    InputError,
    OnlineEstimator,
    PliantError,
    PliantWarning,
    Recording,
    UsageError,
    __version__,
    diagnose,
    estimate,
    make_recording,
    read_recording,
    refine,
    simulate,
    write_recording,
)

__all__ = [
    "__version__",
    "GraspGuard",
    "InputError",
    "OnlineEstimator",
    "PliantError",
    "PliantWarning",
    "Recording",
    "UsageError",
    "diagnose",
    "estimate",
    "make_recording",
    "read_recording",
    "refine",
    "simulate",
    "write_recording",
]
