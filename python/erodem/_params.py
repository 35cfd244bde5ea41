"""Parameters: Python values as (dotted key, TOML value text) pairs for the C++ schema, and
the schema's keys and descriptions (``parameter_keys``, ``parameter_info``).

Strings are quoted by the C++ schema's own ``quoted_string`` (``_erodem.quoted_string``), so
the text given to the schema is written by the same code as ``erodem run --dump-config``.
"""

from __future__ import annotations

import math
import os
from typing import Any, Dict, List, Mapping, Tuple

import numpy as np

from . import _erodem

Settings = List[Tuple[str, str]]


# ---- parameters: Python values -> (dotted key, TOML text) for the C++ schema -----------


def _toml_text(value: Any, key: str) -> str:
    """``value`` (number, bool, string, sequence, mapping, numpy scalar or array) as TOML
    value text. Other types raise ValueError naming the parameter ``key``."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)  # shortest text that reads back to the same double
    if isinstance(value, (str, os.PathLike)):
        return _erodem.quoted_string(os.fspath(value))
    if isinstance(value, Mapping):
        items = ", ".join(
            "%s = %s" % (_erodem.quoted_string(str(k)), _toml_text(v, "%s.%s" % (key, k)))
            for k, v in value.items()
        )
        return "{" + items + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_text(v, key) for v in value) + "]"
    raise ValueError(
        "parameter '%s': cannot use a value of type %s; expected a number, boolean, string "
        "(with a unit, e.g. \"20 mm/h\") or a list" % (key, type(value).__name__)
    )


def _flatten(params: Mapping[str, Any], prefix: str = "") -> Dict[str, Any]:
    """Nested dicts and ``a__b`` names to dotted keys: ``{"erosion": {"min_tilt": 0.1}}``
    and ``erosion__min_tilt=0.1`` both give ``{"erosion.min_tilt": 0.1}``. Lists (e.g. of
    inflow tables) are values, not nested."""
    out: Dict[str, Any] = {}
    for k, v in params.items():
        key = prefix + str(k).replace("__", ".")
        if isinstance(v, Mapping):
            out.update(_flatten(v, key + "."))
        else:
            out[key] = v
    return out


def _settings(params: Mapping[str, Any]) -> Settings:
    """Dotted keys and values as (key, TOML text) pairs, for the C++ schema."""
    return [(k, _toml_text(v, k)) for k, v in _flatten(params).items()]


def parameter_keys() -> List[str]:
    """All parameter names, dotted (``"erosion.sediment_capacity"``), in schema order.

    Returns
    -------
    list of str
        The keys of the TOML config; in Python keywords write ``.`` as ``__``.
    """
    return list(_erodem.parameter_keys())


def parameter_info(key: str) -> Dict[str, str]:
    """What the schema knows about one parameter.

    Parameters
    ----------
    key : str
        Dotted key (``"rain.rate"``) or keyword form (``"rain__rate"``).

    Returns
    -------
    dict
        ``key``, ``type``, ``unit`` (SI unit of the stored value), ``accepted`` (range or
        choices), ``default`` (TOML text) and ``doc``.

    Raises
    ------
    ValueError
        For an unknown key (the message suggests the closest one).
    """
    return dict(_erodem.parameter_info(key.replace("__", ".")))
