"""Helpers below every layer: argument checks, documented fields, warnings, frozen records,
lazy package faces. Standard library only (numpy where a check needs it). Names resolve on
first use, so that ``import chaoscam`` loads none of them."""

from ._lazy import lazy_face

_LAZY = {
    "check_fields": ("._fields", "check_fields"),
    "close_names": ("._fields", "close_names"),
    "COUNT_MAX": ("._checks", "COUNT_MAX"),
    "describe_range": ("._fields", "describe_range"),
    "field_table": ("._fields", "field_table"),
    "flag": ("._checks", "flag"),
    "freeze_fields": ("._frozen", "freeze_fields"),
    "FrozenDict": ("._frozen", "FrozenDict"),
    "meta": ("._fields", "meta"),
    "NON_NEGATIVE": ("._fields", "NON_NEGATIVE"),
    "of_type": ("._checks", "of_type"),
    "ParameterError": ("._fields", "ParameterError"),
    "parse_field": ("._fields", "parse_field"),
    "POSITIVE": ("._fields", "POSITIVE"),
    "quiet": ("._warn", "quiet"),
    "real": ("._checks", "real"),
    "recorded": ("._warn", "recorded"),
    "strict_init": ("._fields", "strict_init"),
    "unknown_message": ("._fields", "unknown_message"),
    "user_stacklevel": ("._warn", "user_stacklevel"),
    "warn": ("._warn", "warn"),
    "whole": ("._checks", "whole"),
}

__all__ = sorted([*_LAZY, "lazy_face"])

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
