"""mbid: multibody identification from Python.

Simulate a machine's test, identify the modes of free-decay records, tune the model's
stiffness and damping to them and validate the result (docs/python.md)."""

import os as _os

from ._mbid import (IdentificationOptions, InputError, ModalResult, Mode, NumericalError,
                    Parameter, Record, Scenario, UpdateResult, ValidationResult, identify,
                    identify_arrays, load_scenario, load_scenario_text, read_record, run,
                    simulate, update)
from ._mbid import default_scenario_path as _default_scenario_path

# Installed as <prefix>/lib/python3/dist-packages/mbid: the data are in <prefix>/share/mbid.
_DATA_DIR = _os.path.normpath(
    _os.path.join(_os.path.dirname(__file__), "..", "..", "..", "..", "share", "mbid"))


def default_scenario_path():
    """The built-in reference scenario (the truck crane's initial-deflection test)."""
    return _default_scenario_path(_DATA_DIR)


__all__ = ["IdentificationOptions", "InputError", "ModalResult", "Mode", "NumericalError", "Parameter", "Record",
           "Scenario", "UpdateResult", "ValidationResult", "default_scenario_path", "identify",
           "identify_arrays", "load_scenario", "load_scenario_text", "read_record", "run",
           "simulate", "update"]
