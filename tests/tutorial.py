#!/usr/bin/env python3
"""Keeps doc/tutorial.md true: runs the commands it shows and checks that
what it says they print is what they print.

  tutorial.py EXE [DOC] [--keep]

EXE replaces the word 'rotorfit' in the commands; DOC defaults to
doc/tutorial.md next to this script. The commands run one block at a time
with bash (-e -o pipefail) in a scratch working copy (a temporary folder with
copies of prm/ and tests/lame.py, the only repository files the tutorial's
commands may use), so their results go there too. The folder is removed when
everything passed (kept with --keep, and always after a failure).

Markers in DOC, each an HTML comment on the line before what it marks:

  <!-- tutorial: command -->
      the next ```bash block is run (stdout and stderr together, as a user
      sees them); it must exit with 0.
  <!-- tutorial: expect [FILE] [rtol=R] [atol=A] -->
      every line of the next ``` block must appear, in this order, in what
      the last command printed (or in FILE, relative to the working copy,
      as the commands so far left it). Runs of blanks count as one blank;
      '...' stands for any text (timings, paths of the machine, round-off
      such as backward errors); a line that is only '...' marks trimmed
      lines and is not matched. Numbers are compared with relative
      tolerance R, default 1e-6: the same binary on the same mesh gives the
      same digits (measured: three runs, byte-identical result files), so
      1e-6 only absorbs the last printed digit; a looser R needs its reason
      next to it in DOC. A (default 0) is an absolute tolerance on top, for
      numbers that are zero up to round-off.
  <!-- tutorial: file PATH -->
      the next ``` block is a part of the repository file PATH; the parts,
      in order and joined by one blank line, must be the whole file, so the
      listings in DOC are the shipped files.
  <!-- tutorial: table columns=2,3 sections=A,B rows="P1 & P2 ; P3 * 1e-6 ; ..." -->
      the next markdown table restates results. Each given column (counted
      from 1) restates what the commands printed under the line '== A'
      (the next, '== B', and so on); each table row names, in rows= (rows
      separated by ' ; '), the printed value of each number in its cells
      (' & ' between the numbers of one cell) as a regular expression that
      the number follows, optionally scaled (' * 1e-6'). Every cell number
      must be exactly that value rounded to the digits shown. Thousands
      separators (16,588) are allowed.

Images that DOC links (![..](path)) must exist. Exit code 0 when all
checks pass, 1 otherwise; every check is printed.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

COPY = ("prm", "tests/lame.py")
NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
MARK = re.compile(r"^<!--\s*tutorial:\s*(\w+)\s*(.*?)\s*-->\s*$")
DEFAULT_RTOL = 1e-6


def normalise(line):
    return " ".join(line.split())


def parse(doc):
    """[(kind, argument, block lines, line number)] in the order of DOC."""
    lines = open(doc, encoding="utf-8").read().split("\n")
    items, i = [], 0
    while i < len(lines):
        m = MARK.match(lines[i].strip())
        if not m:
            i += 1
            continue
        kind, arg, start = m.group(1), m.group(2), i + 1
        j = i + 1
        while j < len(lines) and not lines[j].strip():
            j += 1
        if kind == "table":
            block = []
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                block.append(lines[j])
                j += 1
            if len(block) < 3:
                sys.exit(f"{doc}:{start}: 'tutorial: table' is not followed by a table")
        else:
            if j >= len(lines) or not lines[j].lstrip().startswith("```"):
                sys.exit(f"{doc}:{start}: 'tutorial: {kind}' is not followed by a ``` block")
            fence = lines[j].lstrip()[:3]
            block, j = [], j + 1
            while j < len(lines) and not lines[j].lstrip().startswith(fence):
                block.append(lines[j])
                j += 1
            if j >= len(lines):
                sys.exit(f"{doc}:{start}: unterminated ``` block")
            j += 1
        if kind not in ("command", "expect", "file", "table"):
            sys.exit(f"{doc}:{start}: unknown marker 'tutorial: {kind}'")
        items.append((kind, arg, block, start))
        i = j
    return items


def expect_arguments(arg, where):
    path, rtol, atol = None, DEFAULT_RTOL, 0.0
    for word in arg.split():
        if word.startswith("rtol="):
            rtol = float(word[5:])
        elif word.startswith("atol="):
            atol = float(word[5:])
        elif path is None:
            path = word
        else:
            sys.exit(f"{where}: cannot read 'tutorial: expect {arg}'")
    return path, rtol, atol


def line_pattern(expected):
    """Regex of an expected line ('...' any text, numbers captured) and the
    numbers it shows."""
    out, numbers = [], []
    for k, piece in enumerate(normalise(expected).split("...")):
        if k:
            out.append(".*?")
        for part in re.split("(" + NUM + ")", piece):
            if re.fullmatch(NUM, part):
                out.append("(" + NUM + ")")
                numbers.append(part)
            elif part:
                out.append(re.escape(part))
    return re.compile("".join(out)), numbers


def numbers_agree(got, want, rtol, atol):
    bad = []
    for g, w in zip(got, want):
        a, b = float(g), float(w)
        if abs(a - b) > max(rtol * max(abs(a), abs(b)), atol):
            bad.append(f"{g} (doc: {w})")
    return bad


def match_block(expected, text, rtol, atol, label):
    """Each expected line in TEXT, in order; messages of those that fail."""
    have = [normalise(l) for l in text.split("\n")]
    failures, pos, checked = [], 0, 0
    for line in expected:
        if not line.strip() or normalise(line) == "...":
            continue
        checked += 1
        pattern, want = line_pattern(line)
        found, near = None, None
        for k in range(pos, len(have)):
            m = pattern.fullmatch(have[k])
            if not m:
                continue
            bad = numbers_agree(m.groups(), want, rtol, atol)
            if not bad:
                found = k
                break
            if near is None or len(bad) < len(near[1]):
                near = (have[k], bad)
        if found is not None:
            pos = found + 1
            continue
        earlier = any(pattern.fullmatch(h) and not numbers_agree(
            pattern.fullmatch(h).groups(), want, rtol, atol) for h in have[:pos])
        if earlier:
            failures.append(f"{label}: out of order, found only before the previous "
                            f"expected line:\n    doc: {line.strip()}")
        elif near is None:
            failures.append(f"{label}: not found:\n    doc: {line.strip()}")
        else:
            failures.append(f"{label}: numbers differ (rtol {rtol:g}, atol {atol:g}):\n"
                            f"    doc: {line.strip()}\n    got: {near[0]}\n"
                            f"    differing: {', '.join(near[1])}")
    return checked, failures


def check_files(items, root, doc):
    parts = {}
    for kind, arg, block, start in items:
        if kind == "file":
            parts.setdefault(arg, []).append("\n".join(block))
    failures = []
    for path, blocks in parts.items():
        shown = "\n\n".join(blocks) + "\n"
        actual = open(os.path.join(root, path), encoding="utf-8").read()
        if shown == actual:
            print(f"file {path}: the {len(blocks)} listing(s) in {os.path.basename(doc)} "
                  "are the file: ok")
            continue
        import difflib
        diff = "".join(difflib.unified_diff(actual.splitlines(True), shown.splitlines(True),
                                            path, "listings in the doc"))
        failures.append(f"file {path}: the listings differ from the file:\n{diff}")
    return failures


def check_table(block, arg, printed, label):
    """Each checked cell against the one printed value it restates, to the
    digits shown (see 'tutorial: table' above)."""
    columns, sections, sources = None, None, None
    for word in re.findall(r'(\w+)=("[^"]*"|\S+)', arg):
        key, value = word[0], word[1].strip('"')
        if key == "columns":
            columns = [int(c) - 1 for c in value.split(",")]
        elif key == "sections":
            sections = value.split(",")
        elif key == "rows":
            sources = [row.split(" & ") for row in value.split(" ; ")]
        else:
            sys.exit(f"{label}: cannot read 'tutorial: table {arg}'")
    if not (columns and sections and sources) or len(sections) != len(columns):
        sys.exit(f"{label}: 'tutorial: table' needs columns=, one of sections= per column and rows=")
    rows = block[2:]
    if len(sources) != len(rows):
        sys.exit(f"{label}: rows= names {len(sources)} rows, the table has {len(rows)}")
    failures, n = [], 0
    for column, section in zip(columns, sections):
        # the printed block that follows '== SECTION' (up to the next '== ')
        m = re.search(r"^== " + re.escape(section) + r"\n(.*?)(?=^== |\Z)", printed, re.S | re.M)
        if not m:
            failures.append(f"{label}: nothing printed under '== {section}'")
            continue
        text = m.group(1)
        for row, source in zip(rows, sources):
            cells = [c.strip() for c in row.strip().strip("|").split("|")]
            tokens = re.findall(r"\d{1,3}(?:,\d{3})+(?:\.\d+)?|\d+(?:\.\d+)?(?:[eE][-+]?\d+)?",
                                cells[column])
            if len(tokens) != len(source):
                failures.append(f"{label}: row '{cells[0]}' column {column + 1} has "
                                f"{len(tokens)} numbers, rows= names {len(source)}")
                continue
            for token, pattern in zip(tokens, source):
                n += 1
                pattern, _, scale = pattern.partition(" * ")
                found = re.search(pattern + r"\s*(" + NUM + ")", text, re.M)
                if not found:
                    failures.append(f"{label}: '{pattern}' not printed under '== {section}'")
                    continue
                x = float(found.group(1)) * (float(scale) if scale else 1.0)
                v = float(token.replace(",", ""))
                plain = "." in token and "e" not in token.lower()
                digits = len(token.split(".")[1]) if plain else 0
                if abs(x - v) > 0.5 * 10.0 ** -digits * (1 + 1e-9):
                    failures.append(f"{label}: '{token}' (row '{cells[0]}', {section}) is not "
                                    f"{pattern} = {x:g} rounded to {digits} decimal(s)")
    return n, failures


def main():
    args = [a for a in sys.argv[1:] if a != "--keep"]
    keep = "--keep" in sys.argv[1:]
    if not args:
        sys.exit(__doc__)
    exe = os.path.abspath(args[0])
    here = os.path.dirname(os.path.abspath(__file__))
    doc = os.path.abspath(args[1]) if len(args) > 1 else os.path.join(here, "..", "doc",
                                                                      "tutorial.md")
    root = os.path.dirname(os.path.dirname(doc))
    items = parse(doc)
    name = os.path.relpath(doc, root)

    failures = check_files(items, root, doc)
    for target in re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", open(doc, encoding="utf-8").read()):
        if not os.path.isfile(os.path.join(os.path.dirname(doc), target)):
            failures.append(f"image {target} linked from {name} does not exist")

    work = tempfile.mkdtemp(prefix="rotorfit_tutorial_")
    for path in COPY:
        src, dst = os.path.join(root, path), os.path.join(work, path)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        (shutil.copytree if os.path.isdir(src) else shutil.copy)(src, dst)
    print(f"working copy: {work}")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    word = re.compile(r"(?<![\w./-])rotorfit(?![\w./-])")

    last, printed, n_commands, n_lines, n_numbers = None, [], 0, 0, 0
    for kind, arg, block, start in items:
        label = f"{name}:{start}"
        if kind == "command":
            script = word.sub(lambda m: exe, "\n".join(block))
            print(f"\n$ {chr(10).join(block)}   ({label})")
            t0 = time.time()
            r = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", script], cwd=work, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               timeout=900)
            n_commands += 1
            last = r.stdout
            printed.append(last)
            print(last[-2500:].rstrip() + f"\n[exit code {r.returncode}, {time.time() - t0:.1f} s]")
            if r.returncode != 0:
                failures.append(f"{label}: the command exited with {r.returncode}")
        elif kind == "expect":
            path, rtol, atol = expect_arguments(arg, label)
            if path is not None:
                full = os.path.join(work, path)
                text = open(full).read() if os.path.isfile(full) else None
                if text is None:
                    failures.append(f"{label}: {path} was not written")
                    continue
            elif last is None:
                failures.append(f"{label}: 'expect' before any command")
                continue
            else:
                text = last
            checked, bad = match_block(block, text, rtol, atol, label)
            n_lines += checked
            failures += bad
            if checked == 0:
                failures.append(f"{label}: the expect block has no line to check")
            print(f"{label}: {checked - len(bad)} of {checked} expected lines found"
                  + (f" in {path}" if path else ""))
        elif kind == "table":
            n, bad = check_table(block, arg, "\n".join(printed), label)
            n_numbers += n
            failures += bad
            print(f"{label}: {n - len(bad)} of {n} table numbers printed by the commands")

    print(f"\n{name}: {n_commands} commands, {n_lines} expected lines, {n_numbers} table numbers")
    if n_commands == 0 or n_lines == 0:
        failures.append(f"{name}: no marked command or expected output: nothing was checked")
    text = open(doc, encoding="utf-8").read().split("\n")
    marked = {start for kind, arg, block, start in items}
    for k, line in enumerate(text):
        if line.strip().startswith("```bash") and not any(m <= k < m + 2 for m in marked):
            print(f"note: {name}:{k + 1}: a bash block without 'tutorial: command' is not run")
    if failures:
        print("\n".join(["", "FAILED:"] + failures))
        print(f"(working copy kept: {work})")
        return 1
    if keep:
        print(f"working copy kept: {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    print("tutorial: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
