#!/usr/bin/env python3
"""Write doc/parameters.md from what rotorfit declares.

    parameters_md.py ROTORFIT OUTPUT.md

runs `ROTORFIT --print-parameters json` and writes one table per subsection
(entry, default, allowed values, meaning). The build writes it into the
build folder; the test parameters_doc fails when doc/parameters.md differs;
`cmake --build build --target update_parameters_doc` copies it into doc/.
"""
import json
import re
import subprocess
import sys


def allowed(pattern):
    """deal.II's pattern description, shortened for a reader."""
    p = pattern.strip()
    mandatory = p.endswith(" (mandatory)")
    if mandatory:
        return allowed(p[: -len(" (mandatory)")]) + ", mandatory"
    if p.startswith("[") and p.endswith("]"):
        p = p[1:-1]
    for big in ("MAX_DOUBLE", "1.79769e+308", "4294967295", "2147483647", "MAX_INT"):
        p = p.replace("-" + big, "-inf").replace(big, "inf")
    p = p.replace("-2147483648", "-inf").replace("Integer range", "Integer")
    p = re.sub(r"List of <\[(.*?)\]> of length 0\.\.\.inf \(inclusive\)",
               lambda m: "list of " + allowed(m.group(1)), p)
    p = re.sub(r"(Double|Integer) -inf\.\.\.inf \(inclusive\)", r"any \1", p)
    p = re.sub(r"(Double|Integer) (\S+)\.\.\.inf \(inclusive\)", r"\1 >= \2", p)
    p = re.sub(r"(Double|Integer) (\S+)\.\.\.(\S+) \(inclusive\)", r"\1 \2 .. \3", p)
    p = p.replace("Double > 0", "number > 0")
    p = p.replace("Double", "number").replace("Integer", "integer")
    p = re.sub(r"Selection (.*)", lambda m: "one of " + ", ".join(
        f"`{s.strip()}`" for s in m.group(1).split("|")), p)
    if p == "Anything":
        return "text"
    if p == "list of text":
        return "list of names"
    return p.replace("...", " .. ").replace("|", "\\|")


def cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def is_entry(node):
    return isinstance(node, dict) and "default_value" in node


def table(entries):
    rows = ["| Entry | Default | Allowed | Meaning |", "|---|---|---|---|"]
    for name, e in entries:
        default = f"`{e['default_value']}`" if e["default_value"] != "" else "(empty)"
        rows.append(f"| {cell(name)} | {cell(default)} | {allowed(e['pattern_description'])} "
                    f"| {cell(e['documentation'])} |")
    return "\n".join(rows)


def sections(node, path):
    entries = sorted((k, v) for k, v in node.items() if is_entry(v))
    subs = sorted((k, v) for k, v in node.items() if not is_entry(v) and isinstance(v, dict))
    out = []
    if entries:
        title = "/".join(path) if path else "Top level"
        out.append((title, table(entries)))
    for k, v in subs:
        out += sections(v, path + [k])
    return out


def main(exe, output):
    r = subprocess.run([exe, "--print-parameters", "json"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{exe} --print-parameters json failed: {r.stderr}")
    tree = json.loads(r.stdout)
    parts = ["# rotorfit parameters", "",
             "Generated from `rotorfit --print-parameters json` by `scripts/parameters_md.py` "
             "when rotorfit is built; do not edit by hand. After changing a declaration, "
             "`cmake --build build --target update_parameters_doc` copies the new version "
             "here; the test `parameters_doc` fails while this file differs from the code.",
             "",
             "A `.prm` file sets entries with `set Entry = value` inside "
             "`subsection Name ... end`. `<name>` stands for each name listed in `Bodies`, "
             "`Interfaces` or `Bearings` (e.g. `subsection Body shaft`). "
             "`rotorfit --print-parameters` prints every entry with its default as a "
             "`.prm` file to start from.", ""]
    for title, body in sections(tree, []):
        parts += [f"## {title}", "", body, ""]
    open(output, "w").write("\n".join(parts))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
