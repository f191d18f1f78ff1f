"""``vipvflow config``: validate a scenario file and print the resolved configuration."""
from __future__ import annotations

import yaml

from ..config import load_config
from . import add_config


def register(sub):
    p = sub.add_parser("config", help="validate a scenario YAML and print the merged configuration")
    add_config(p)
    p.set_defaults(func=run)


def run(args):
    cfg = load_config(args.config)
    print(yaml.safe_dump(cfg.model_dump(mode="json"), sort_keys=False), end="")
    print(f"# pv system: {cfg.pv_system().model_dump()}")
    return 0
