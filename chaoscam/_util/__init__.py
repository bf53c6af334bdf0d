"""Helpers below every layer: argument checks, documented fields, warnings, frozen records,
lazy package faces. Standard library only (numpy where a check needs it)."""

from ._checks import COUNT_MAX, flag, of_type, real, whole
from ._fields import (
    NON_NEGATIVE,
    POSITIVE,
    ParameterError,
    check_fields,
    close_names,
    describe_range,
    field_table,
    meta,
    parse_field,
    strict_init,
    unknown_message,
)
from ._frozen import FrozenDict, freeze_fields
from ._lazy import lazy_face
from ._warn import quiet, recorded, user_stacklevel, warn

__all__ = [
    "COUNT_MAX", "NON_NEGATIVE", "POSITIVE", "FrozenDict", "ParameterError", "check_fields",
    "close_names", "describe_range", "field_table", "flag", "freeze_fields", "lazy_face", "meta",
    "of_type", "parse_field", "quiet", "real", "recorded", "strict_init", "unknown_message",
    "user_stacklevel", "warn", "whole",
]  # fmt: skip
