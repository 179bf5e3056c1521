"""The one table of caps on the work a file from elsewhere can ask for.

A scenario, a recipe, a hyperparameter file, a model zip, its statistics, a benchmark result
or a demonstrations file is small on disk, but a count inside it (bodies, goals after a path
expands, waypoints, network widths, simulation substeps, array rows) multiplies the work of
loading or running it. Each count is checked against :data:`CAPS` before that work starts,
and a file over a cap gets one line naming the file, the field and the cap. The table lives
at the bottom layer so that the scenario parser and the model, demonstration and benchmark
loaders above it read the same numbers; docs/untrusted-files.md shows it with the reasons,
and the tests try each cap just under and just over.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["CAPS", "Cap", "cap", "caps_markdown"]

MIB = 1 << 20


class Cap(NamedTuple):
    """The largest value a file may ask for, what it counts and why it is where it is."""

    limit: int
    unit: str
    counts: str
    reason: str


CAPS: dict[str, Cap] = {
    "file_bytes": Cap(
        8 * MIB, "bytes",
        "a text file read whole: scenario, recipes, hyperparameters, VecNormalize statistics, "
        "a model's `data` member and `config.json`, a benchmark's `result.json`/`failed.json`",
        "parsing costs 10-100 times the text in memory; the largest shipped text file is 15 KB, "
        "the largest model `data` member 185 KB"),
    "yaml_bytes": Cap(
        1 * MIB, "bytes", "the text of a YAML file: scenario, recipes, hyperparameters",
        "reading YAML builds Python objects for every value as it goes (~15 us each, 1.6 MB "
        "took 15 s); a scenario at the waypoint or goal cap is ~0.5 MB"),
    "nesting": Cap(
        64, "levels", "nesting of lists and mappings in a YAML or JSON document",
        "the parsers and every walk over the data recurse once per level (Python stops at "
        "1000); the deepest shipped file has 6"),
    "data_nodes": Cap(
        250_000, "values", "values in a YAML or JSON document, an alias counted at each use",
        "a YAML alias repeats a subtree without repeating its text (1 KB can stand for "
        "billions of values), and building each value costs ~10 us: 250,000 take ~3 s; "
        "a scenario at every other cap has ~100,000"),
    "bodies": Cap(
        32, "bodies", "bodies of a scenario",
        "each body is planned and checked when the scenario loads (~0.1 s) and simulated "
        "every substep; the largest shipped scene has 3"),
    "props": Cap(
        32, "props", "props (moving obstacles, targets) of a scenario",
        "each prop's path is sampled at every substep of the episode"),
    "goals": Cap(
        10_000, "goals", "goals of a scenario, counted after every path goal expands",
        "each goal is routed, planned and observed; 10,000 load in ~3 s"),
    "path_samples": Cap(
        1_000, "samples", "samples of one point-to-path goal",
        "each sample is a goal of its own and needs at least one control tick"),
    "helix_turns": Cap(
        1_000, "turns", "turns of a helix path",
        "a curve is sampled 64 times per sample interval; more turns than samples is aliasing"),
    "polyline_points": Cap(
        1_000, "points", "waypoints of a polyline path",
        "the curve is interpolated through every point at each of 65 x samples evaluations"),
    "prop_waypoints": Cap(
        10_000, "waypoints", "waypoints of one prop",
        "a prop's position is interpolated through them at every substep"),
    "sim_frequency": Cap(
        10_000, "Hz", "`sim_frequency` from `--env-kwargs`, a recipe or a demonstrations file",
        "every control tick runs sim_frequency / control_frequency PyBullet steps; 10 kHz is "
        "40 times the default 240 Hz"),
    "n_envs": Cap(
        256, "envs", "`n_envs` of a hyperparameter file",
        "each env is a PyBullet world or a batched slot of its own; the shipped recipes use up "
        "to 64"),
    "model_file_bytes": Cap(
        256 * MIB, "bytes", "a model zip on disk (it is read whole, once)",
        "the shipped models are under 1 MB; a 4096-wide net with its optimizer is ~200 MB"),
    "zip_members": Cap(
        64, "members", "members of a model zip",
        "SB3 writes six; each member is read once to check it"),
    "zip_member_bytes": Cap(
        128 * MIB, "bytes", "a model zip member's uncompressed size (as declared, and as read)",
        "a 9 MB zip can hold an 8 GiB member that decompresses into memory"),
    "net_width": Cap(
        4096, "units", "width of a layer in `net_arch` and of a features extractor",
        "weights grow with the square of the width: [8000]*4 took 2.6 GB and a minute"),
    "net_layers": Cap(
        16, "layers", "hidden layers in `net_arch` (per head)",
        "every layer is built and run at each step; the shipped nets have 2-3"),
    "net_parameters": Cap(
        16_000_000, "weights", "weights of the hidden layers `net_arch` asks for",
        "64 MB of float32 weights, 256 MB with Adam's moments and gradients"),
    "demo_rows": Cap(
        2_000_000, "rows", "steps (rows) of a demonstrations npz",
        "behaviour cloning runs epochs over every row; `sgc demos` writes ~300 per episode"),
    "npz_array_bytes": Cap(
        512 * MIB, "bytes", "one array of a demonstrations npz, from its header's shape",
        "a header can claim 10^12 rows in a few bytes; the array is allocated before read"),
}  # fmt: skip
"""Cap name -> :class:`Cap`. A value equal to the limit is allowed, one above is refused."""


def cap(name: str) -> int:
    """The limit of cap ``name``."""
    return CAPS[name].limit


def caps_markdown() -> str:
    """The table of docs/untrusted-files.md, written from :data:`CAPS`."""
    rows = ["| cap | limit | counts | why |", "|---|---|---|---|"]
    rows += [f"| `{name}` | {c.limit:,} {c.unit} | {c.counts} | {c.reason} |"
             for name, c in CAPS.items()]  # fmt: skip
    return "\n".join(rows) + "\n"

