"""`mtt-sim config`: the configuration reference, or one scenario's configuration with the overrides applied."""

from __future__ import annotations

import json

from mtt_sim.cli.arguments import (CONFIG_HELP, SCENARIO_HELP, UsageError, add_overrides, episode_overrides, loaded,
                                   scenario_key)
from mtt_sim import sources
from mtt_sim.sim import scenario


def add(subparsers) -> None:
    p = subparsers.add_parser("config", help="the configuration reference, or one scenario's resolved configuration")
    p.add_argument("scenario", nargs="?", type=scenario_key, help=SCENARIO_HELP)
    add_overrides(p, CONFIG_HELP)
    p.set_defaults(func=run)


def run(args) -> int:
    overrides = episode_overrides(args)
    if overrides and not args.scenario:
        given, value = (("--config", " ".join(args.config)) if args.config else ("--detector", args.detector)
                        if args.detector else ("--sensor", args.sensor))
        raise UsageError(given, f"{value!r}: overrides apply to a scenario; name one (mtt-sim config mot17_like "
                                f"{given} ...)")
    if args.scenario:
        loaded([args.scenario], overrides)
        print(json.dumps(scenario.to_mapping(sources.open_source(args.scenario, overrides).config), indent=2))
    else:
        print(scenario.reference_table())
    return 0
