"""The workcell file (TOML, docs/workcell-file.md): its reader and writer live with the
description they read (:mod:`regrasp.workcell.description`); this module keeps their names."""

from .description import (BUNDLED, KEYS, bundled, from_dict, from_toml, load, save, to_dict, to_toml,
                          toml_value)

__all__ = ["BUNDLED", "KEYS", "bundled", "from_dict", "from_toml", "load", "save", "to_dict", "to_toml", "toml_value"]
