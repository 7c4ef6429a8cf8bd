#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
# Writes the navigate inputs a simulated case lacks, from its truth.json: tools/reference.json
# (the headframe tools joined in the first tool's frame), tools/<tool>.json for each tool and
# tool_from_image.json (the true registration of the reference).
import json
import sys
from pathlib import Path

import numpy as np


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: navigation_case_from_truth.py CASE_DIR", file=sys.stderr)
        return 2
    case = Path(sys.argv[1])
    header = {}
    with open(case / "truth.json") as f:
        text = f.read()
    # The truth file streams one frame per line; the header keys precede "frames".
    header = json.loads(text)
    tools = header["tools"]
    # The headframe tools: rigid with the patient and named reference* (evd-usecase: two).
    joined = [n for n, t in tools.items()
               if t.get("rigid_with_patient") and n.startswith("reference")]
    if not joined:
        print("no reference* tool rigid with the patient", file=sys.stderr)
        return 1
    (case / "tools").mkdir(exist_ok=True)
    for name, t in tools.items():
        m = t["markers"]
        doc = {"name": name, "markers": [x["centre_in_tool"] for x in m],
               "marker_type": "sphere" if m[0]["shape"] == "sphere" else "flat",
               "marker_diameter_mm": m[0]["diameter_mm"]}
        (case / "tools" / f"{name}.json").write_text(json.dumps(doc, indent=2) + "\n")
    first = joined[0]
    mount_from_first = np.array(tools[first]["mount_from_tool"])
    markers = []
    for name in joined:
        first_from_tool = np.linalg.inv(mount_from_first) @ np.array(tools[name]["mount_from_tool"])
        for m in tools[name]["markers"]:
            markers.append((first_from_tool @ np.append(m["centre_in_tool"], 1.0))[:3].tolist())
    shape = tools[first]["markers"][0]["shape"]
    reference = {"name": "Reference", "markers": markers,
                 "marker_type": "sphere" if shape == "sphere" else "flat",
                 "marker_diameter_mm": tools[first]["markers"][0]["diameter_mm"]}
    (case / "tools" / "reference.json").write_text(json.dumps(reference, indent=2) + "\n")
    registration = {"target_frame": "tool", "source_frame": "image", "units": "mm",
                    "target_from_source": header[f"{first}_from_image"]}
    (case / "tool_from_image.json").write_text(json.dumps(registration, indent=2) + "\n")
    print(f"reference = {' + '.join(joined)} ({len(markers)} markers) in the frame of {first}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
