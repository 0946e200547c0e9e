# SPDX-License-Identifier: BSD-2-Clause
"""Calibration of the plant to a real machine (docs/calibration.md): the
regressor's parameters and base parameters (parameters), an exciting
trajectory (excitation), identification from a drive log (identification)
and drive logs made by the plant FMU (drive_log). Needs scipy."""
from .excitation import FourierTrajectory, Limits, optimise_excitation, random_trajectory
from .identification import IdentificationError, IdentificationResult, filtered_derivatives, identify
from .parameters import BaseParameters, base_parameters, make_plant

__all__ = ["FourierTrajectory", "Limits", "optimise_excitation", "random_trajectory", "IdentificationError", "IdentificationResult",
           "filtered_derivatives", "identify", "BaseParameters", "base_parameters", "make_plant"]
