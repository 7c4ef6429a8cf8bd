#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
# Writes the navigate inputs a simulated case lacks: tools/reference.json (a copy of the joined
# headframe tool that tofnav simulate writes, tools/headframe.json) and tool_from_image.json (the
# true registration of the headframe, truth.json's headframe_from_image).
import json
import shutil
import sys
from pathlib import Path


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: navigation_case_from_truth.py CASE_DIR", file=sys.stderr)
        return 2
    case = Path(sys.argv[1])
    truth = json.loads((case / "truth.json").read_text())
    headframe = case / "tools" / "headframe.json"
    if not headframe.exists() or "headframe_from_image" not in truth:
        print("no joined headframe tool (tools/headframe.json, headframe_from_image): the case "
              "needs two reference* tools rigid with the patient", file=sys.stderr)
        return 1
    shutil.copyfile(headframe, case / "tools" / "reference.json")
    registration = {"target_frame": "tool", "source_frame": "image", "units": "mm",
                    "target_from_source": truth["headframe_from_image"]}
    (case / "tool_from_image.json").write_text(json.dumps(registration, indent=2) + "\n")
    markers = len(json.loads(headframe.read_text())["markers"])
    print(f"reference = tools/headframe.json ({markers} markers)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
