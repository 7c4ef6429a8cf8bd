#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The markdown table of scripts/profile_costs.sh: one row per (session, stream profile) with
every stage's figure against the simulator's truth and the bitrate measured on the stream.
Usage: profile_costs_table.py OUT_DIR CONFIG...  (CONFIG as in profile_costs.sh)"""
import json
import math
import os
import sys

CASES = ("phantom-spheres", "phantom-discs", "ct-spheres", "mr-discs")  # profile_costs.sh --only


def num(value):
    return value if isinstance(value, (int, float)) and not math.isnan(value) else None


def fmt(value, decimals):
    return "-" if num(value) is None else f"{value:.{decimals}f}"


def figures(stages):
    """Every stage's figure from a demo.json "stages" object (the suite keeps the same)."""
    get = lambda stage, key: stages.get(stage, {}).get(key)
    tools = [t for t in stages.get("tracking", {}).get("tools", []) if t["name"].startswith("reference")]
    head = [o for o in stages.get("depth", {}).get("objects", []) if o.get("target")]
    return {
        "frf_mm": get("marker_error", "bias_after_max_abs_mm"),
        "track_mm": max((t["filtered_position_rms_mm"] for t in tools), default=None),
        "track_deg": max((t["filtered_rotation_rms_deg"] for t in tools), default=None),
        "depth_mm": abs(head[0]["after_median_mm"]) if head else None,
        "recon_mm": get("reconstruction", "median_mm"),
        "beyond3_pct": get("reconstruction", "beyond_3mm_percent"),
        "tre_mm": get("registration", "tre_mm"),
        "entry_mm": get("guidance", "entry_median_mm"),
        "angle_deg": get("guidance", "angle_median_deg"),
        "mbit_s": get("session", "stream_mbit_s"),
        "errors": "; ".join(f"{k}: {v['error']}" for k, v in stages.items() if not v.get("ok", True)),
    }


def label(config):
    profile, _, bitrate = config.partition(":")
    return profile + (f" @ {int(bitrate) / 1e6:.2f} Mbit/s" if bitrate else " (default)")


def main():
    out, configs = sys.argv[1], sys.argv[2:]
    rows = {}  # session -> config -> figures
    for config in configs:
        name = config.replace(":", "_").replace("+", "_")
        demo = os.path.join(out, f"demo_{name}.json")
        if os.path.exists(demo):
            rows.setdefault("demo seed 1", {})[config] = figures(json.load(open(demo))["stages"])
        suite = os.path.join(out, f"suite_{name}.json")
        if os.path.exists(suite) and os.path.getsize(suite) > 0:
            for row in json.load(open(suite))["rows"]:
                if row["name"] in CASES:  # a whole suite's file may stand in for the four cases
                    rows.setdefault(row["name"], {})[config] = figures(row.get("stages", {}))
    print("| session | stream | Mbit/s | f_rf bias mm | tracking mm / deg | head depth mm | "
          "recon mm | > 3 mm % | true TRE mm | entry mm | angle deg |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for session, by_config in rows.items():
        for config in configs:
            f = by_config.get(config)
            if f is None:
                continue
            print(f"| {session} | {label(config)} | {fmt(f['mbit_s'], 2)} | {fmt(f['frf_mm'], 3)} | "
                  f"{fmt(f['track_mm'], 2)} / {fmt(f['track_deg'], 2)} | {fmt(f['depth_mm'], 2)} | "
                  f"{fmt(f['recon_mm'], 3)} | {fmt(f['beyond3_pct'], 2)} | {fmt(f['tre_mm'], 2)} | "
                  f"{fmt(f['entry_mm'], 2)} | {fmt(f['angle_deg'], 2)} |"
                  + (f" {f['errors']}" if f["errors"] else ""))


if __name__ == "__main__":
    main()
