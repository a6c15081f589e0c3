#!/usr/bin/env python3
"""Writes single-light copies of shipped setups, for `shadowlab tune` and `sweep`, whose
--light picks one index for every setup: `one-light-setups.py OUTDIR SETUP:INDEX...` writes
OUTDIR/<stem>-l<INDEX>.toml holding the setup with only its light INDEX. Relative scene paths
are made absolute, so OUTDIR may be anywhere. Used for the tune of issue 48 (docs/bench/warp.md)."""
import os
import re
import sys

# a table header line: [name] or [[name]]
SECTION = re.compile(r"(?m)^(?=\[\[?[A-Za-z_][\w.]*\]\]?\s*$)")


def one_light(setup, index, outdir):
    text = open(setup).read()
    parts = SECTION.split(text)
    lights = [p for p in parts if p.startswith("[[lights]]")]
    if not 0 <= index < len(lights):
        sys.exit(f"error: {setup} has {len(lights)} lights, no light {index}")
    out, placed = [], False
    for p in parts:
        if p.startswith("[[lights]]"):
            if not placed:
                out.append(lights[index])
                placed = True
        elif p.startswith("[scene]"):
            base = os.path.dirname(os.path.abspath(setup))
            out.append(re.sub(r'(?m)^path = "([^"/][^"]*)"',
                              lambda m: 'path = "%s"' % os.path.normpath(os.path.join(base, m.group(1))), p))
        else:
            out.append(p)
    stem = os.path.splitext(os.path.basename(setup))[0]
    dst = os.path.join(outdir, f"{stem}-l{index}.toml")
    with open(dst, "w") as f:
        f.write(f"# {setup} with its light {index} only (scripts/one-light-setups.py)\n" + "".join(out))
    return dst


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    os.makedirs(sys.argv[1], exist_ok=True)
    for arg in sys.argv[2:]:
        setup, _, index = arg.rpartition(":")
        print(one_light(setup, int(index), sys.argv[1]))
