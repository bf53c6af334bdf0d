"""Helpers below every layer: argument checks, documented fields, warnings, frozen records,
lazy package faces. Standard library only (numpy where a check needs it). Names resolve on
first use, so that ``import chaoscam`` loads none of them."""

from ._lazy import lazy_face

_LAZY = {
    "COUNT_MAX": ("._checks", "COUNT_MAX"), "flag": ("._checks", "flag"),
    "real": ("._checks", "real"), "whole": ("._checks", "whole"),
    "check_fields": ("._fields", "check_fields"), "close_names": ("._fields", "close_names"),
    "field_table": ("._fields", "field_table"), "meta": ("._fields", "meta"),
    "ParameterError": ("._fields", "ParameterError"),
    "parse_field": ("._fields", "parse_field"), "strict_init": ("._fields", "strict_init"),
    "unknown_message": ("._fields", "unknown_message"),
    "freeze_fields": ("._frozen", "freeze_fields"), "FrozenDict": ("._frozen", "FrozenDict"),
    "quiet": ("._warn", "quiet"), "recorded": ("._warn", "recorded"),
    "user_stacklevel": ("._warn", "user_stacklevel"), "warn": ("._warn", "warn"),
}  # fmt: skip

__all__ = sorted([*_LAZY, "lazy_face"])

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
