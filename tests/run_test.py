#!/usr/bin/env python3
"""CTest driver for rotorfit. Each check says what it compares against (a
closed form, an independently known value, another path of the same code,
or the message of a refusal); the tolerances are stated in
tests/CMakeLists.txt, and so is each test's kind (its CTest label).

  run_test.py compare EXE PRM OUTDIR EXPECTED RTOL ATOL [NP]
      run the case, take the keys of EXPECTED from OUTDIR/summary.txt and
      compare them with numdiff (relative RTOL, absolute ATOL). A key
      SUB/KEY is read from the subfolder SUB (a fit study's case), a key
      FILE.csv:SPEED:NAME:COLUMN from a result table.
  run_test.py error EXE PRM EXPECTED [OPTIONS...]
      --validate [OPTIONS] must fail with exit code 1; stderr is compared with EXPECTED
      (numdiff, numbers to 1e-6 relative).
  run_test.py static_flags EXE PRM OUTDIR TEXT [LIMIT]
      an unconverged static state flagged in contact.csv, campbell.csv,
      summary.txt and the log (see static_flags()).
  run_test.py lock_and_signal EXE PRM OUTDIR
      a second run into a busy folder is refused; SIGTERM stops the first.
  run_test.py locked EXE PRM OUTDIR
      --validate refuses a folder whose lock another process holds.
  run_test.py csv_fields EXE PRM OUTDIR TEXT
      every CSV row has its header's field count; a status with TEXT and a
      comma is quoted.
  run_test.py plot_warning EXE PRM_LATIN1 PRM OUTDIR
      a picture that fails names the script's error; matplotlib only when
      its import failed.
  run_test.py areas EXE PRM EXPECTED
      --validate accepts PRM and reports the interface/bearing areas of
      EXPECTED ('area.NAME value rtol' lines; numdiff).
  run_test.py softening EXE PRM_OFF OUT_OFF PRM_ON OUT_ON EXPECTED
      losses of fit with spin softening off/on and their shift against
      EXPECTED (exact values of tests/lame.py; numdiff).
  run_test.py prints EXE PRM EXPECTED [OPTIONS...]
      --validate [OPTIONS] PRM prints the lines of EXPECTED (as parts of its
      lines), in order.
  run_test.py parameters_doc GENERATED DOC
      DOC equals GENERATED (the build's parameters.md).
  run_test.py slip_steps EXE PRM OUTDIR INTERFACE RTOL [SETS...]
      the slip speed with 2 speeds and with a dense list agrees (exact path).
  run_test.py valid EXE PRM
      --validate accepts PRM.
  run_test.py ratio EXE PRM_A OUT_A PRM_B OUT_B KEY EXPECTED RTOL
      run two cases; KEY(A)/KEY(B) must equal EXPECTED within RTOL (numdiff).
  run_test.py same EXE PRM OUTDIR_1 OUTDIR_2 RTOL
      contact.csv with 1 and 2 MPI ranks must agree in every column (RTOL
      relative, or the column's absolute tolerance in CONTACT_ATOL).
"""
import re
import os
import subprocess
import sys


def numdiff(a, b, rtol, atol):
    sep = ["-s", " \t\n,"]  # CSV fields are numbers of their own
    r = subprocess.run(["numdiff", "-q", *sep, "-r", str(rtol), "-a", str(atol), a, b])
    if r.returncode != 0:
        subprocess.run(["numdiff", *sep, "-r", str(rtol), "-a", str(atol), a, b])
        print(f"--- {a}\n" + open(a).read())
    return r.returncode


def run(exe, prm, np=1, outdir=None):
    """Run the case; PRM is a path or a list of arguments (see case());
    OUTDIR, if given, goes to --output (the .prm is never edited)."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    args = list(prm) if isinstance(prm, list) else ([] if outdir is None else
                                                    ["--output", outdir]) + [prm]
    cmd = [exe] + args if np == 1 else ["mpirun", "-np", str(np), exe] + args
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    sys.stdout.write(r.stdout[-3000:])
    sys.stderr.write(r.stderr[-3000:])
    if r.returncode != 0:
        sys.exit(f"rotorfit exited with {r.returncode}")
    if outdir is not None:
        # the effective parameters record where the results went
        used = open(os.path.join(outdir, "parameters.prm")).read()
        if not re.search(r"set Directory\s*=\s*" + re.escape(outdir) + r"\s*$", used, re.M):
            sys.exit(f"{outdir}/parameters.prm does not record --output {outdir}")


def case(prm, outdir, sets=()):
    """Arguments that run PRM into OUTDIR; SETS ('Subsection/Entry=value')
    go to --set, so a variant of a case (a finer mesh, say) needs no copy of
    its .prm."""
    args = ["--output", outdir]
    for s in sets:
        args += ["--set", s]
    return args + [prm]


def pictures(exe, prm, outdir, scripts_dir, python, *sets):
    """Run PRM (with --set SETS) and check the pictures the run drew (PYTHON:
    the interpreter with matplotlib the run itself uses): each
    expected PNG exists, and each script, run again with --check-labels,
    finds no label that overlaps another or leaves the frame."""
    run(exe, case(prm, outdir, sets))
    summary = open(os.path.join(outdir, "summary.txt")).read()
    ok = True
    jobs = [("plot_campbell.py", ["campbell.png"])]
    if os.path.exists(os.path.join(outdir, "response.csv")):
        jobs.append(("plot_response.py", ["response_bode.png", "response_polar.png"]))
    if open(os.path.join(outdir, "contact.csv")).read().count("\n") > 1:
        jobs.append(("plot_contact.py", ["contact.png"]))
    fit = os.path.join(outdir, "fit.csv")
    if os.path.exists(fit) and open(fit).read().count("\n") > 1:
        jobs.append(("plot_fit.py", ["fit.png"]))
    for script, pngs in jobs:
        for png in pngs:
            there = os.path.getsize(os.path.join(outdir, png)) > 0 if os.path.exists(
                os.path.join(outdir, png)) else False
            print(f"{png} drawn by the run:", "ok" if there else "FAILED")
            ok &= there
        r = subprocess.run([python, os.path.join(scripts_dir, script), outdir,
                            "--check-labels"], capture_output=True, text=True)
        print(r.stdout[-2000:], r.stderr[-2000:])
        print(f"{script} --check-labels:", "ok" if r.returncode == 0 else "FAILED")
        ok &= r.returncode == 0
    print("run.status completed:", "ok" if "run.status completed" in summary else "FAILED")
    ok &= "run.status completed" in summary
    return 0 if ok else 1


def falls(exe, prm, outdir):
    """Contact fraction of every interface: 1 at the first speed, then
    strictly decreasing once below 1, and still > 0 (partial opening); the
    asymmetry measure and the loss-of-fit speed consistent (see below)."""
    run(exe, prm, outdir=outdir)
    import csv
    rows = list(csv.DictReader(open(os.path.join(outdir, "contact.csv"))))
    ok = True
    for name in sorted({r["interface"] for r in rows}):
        f = [(float(r["speed_rpm"]), float(r["contact_fraction"])) for r in rows
             if r["interface"] == name]
        print(name, f)
        ok &= abs(f[0][1] - 1) < 1e-12
        opened = [x for x in f if x[1] < 1]
        ok &= len(opened) >= 2 and all(b[1] < a[1] for a, b in zip(opened, opened[1:]))
        ok &= f[-1][1] > 0
        # the asymmetry measure (consistency): exactly 0 on a closed fit,
        # within [0, 1] everywhere, and the log warns exactly above 0.5
        a = [(float(r["contact_fraction"]), float(r["asymmetry"])) for r in rows
             if r["interface"] == name]
        print(name, "asymmetry", [x[1] for x in a])
        ok &= all(x[1] == 0 for x in a if x[0] == 1) and all(0 <= x[1] <= 1 for x in a)
        warned = "not rotationally symmetric" in open(os.path.join(outdir, "log.txt")).read()
        ok &= warned == any(x[1] > 0.5 for x in a)
        # one loss-of-fit speed: the last row of contact.csv and summary.txt
        last = [r for r in rows if r["interface"] == name][-1]
        lof = summary_value(outdir, f"interface.{name}.loss_of_fit_rpm")
        print(name, "loss of fit: contact.csv", last["loss_of_fit_rpm"], "summary.txt", lof)
        ok &= abs(float(last["loss_of_fit_rpm"]) / lof - 1) < 1e-7
    print("contact fraction falls with speed:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def result_value(outdir, key):
    """KEY of OUTDIR's summary.txt; 'SUB/KEY': of the subfolder SUB (a fit study's case);
    'FILE.csv:SPEED:NAME:COLUMN': COLUMN of the row at SPEED r/min whose second field is NAME."""
    if "/" in key:
        sub, key = key.split("/", 1)
        return result_value(os.path.join(outdir, sub), key)
    if ".csv:" in key:
        name, speed, item, column = key.split(":")
        lines = [l.rstrip("\n").split(",") for l in open(os.path.join(outdir, name))]
        col = lines[0].index(column)
        for f in lines[1:]:
            if float(f[0]) == float(speed) and f[1] == item:
                return f[col]
        return None
    for l in open(os.path.join(outdir, "summary.txt")):
        if l.strip() and l.split(None, 1)[0] == key:
            return l.split(None, 1)[1].strip()
    return None


def compare(exe, prm, outdir, expected, rtol, atol, np="1"):
    run(exe, prm, int(np), outdir)
    # each line: key value [rtol atol]; a line's own tolerances override
    failed = 0
    for line in open(expected):
        if not line.strip() or line.startswith("#"):
            continue
        f = line.split()
        key, value = f[0], f[1]
        r, a = (f[2], f[3]) if len(f) >= 4 else (rtol, atol)
        have = result_value(outdir, key)
        if have is None:
            sys.exit(f"{key} missing from the results in {outdir}")
        safe = re.sub(r"[^A-Za-z0-9_.]", "_", key)
        got, want = (os.path.join(outdir, safe + s) for s in (".got", ".want"))
        open(got, "w").write(f"{safe} {have}\n")
        open(want, "w").write(f"{safe} {value}\n")
        status = numdiff(got, want, r, a)
        print(f"{key}: {have} vs {value} (rtol {r}, atol {a}):",
              "ok" if status == 0 else "FAILED")
        failed += status != 0
    return 1 if failed else 0


def summary_value(outdir, key):
    for line in open(os.path.join(outdir, "summary.txt")):
        if line.split()[0] == key:
            return float(line.split()[1])
    sys.exit(f"{key} missing from {outdir}/summary.txt")


def ratio(exe, prm_a, out_a, prm_b, out_b, keys, expected, rtol):
    """KEYS: comma-separated; each KEY(A)/KEY(B) must equal EXPECTED."""
    run(exe, prm_a, outdir=out_a)
    run(exe, prm_b, outdir=out_b)
    failed = 0
    for key in keys.split(","):
        a, b = summary_value(out_a, key), summary_value(out_b, key)
        got, want = os.path.join(out_a, key + ".ratio.got"), os.path.join(out_a, key + ".ratio.want")
        open(got, "w").write(f"{key}_ratio {a / b:.10g}\n")
        open(want, "w").write(f"{key}_ratio {expected}\n")
        status = numdiff(got, want, rtol, 0)
        print(f"{key}: {a} / {b} = {a / b} vs {expected} (rtol {rtol}):",
              "ok" if status == 0 else "FAILED")
        failed += status != 0
    return 1 if failed else 0


def softening(exe, prm_off, out_off, prm_on, out_on, expected):
    """Plane-strain fit with spin softening off and on against EXPECTED: the
    exact losses of fit (tests/lame.py, Bessel J1/Y1 with softening) and the
    shift on/off - 1 (same mesh, so the discretisation error of the speed
    itself cancels), each line 'key value rtol', diffed with numdiff. The
    file's '# lame:' line holds the arguments of lame.py; values that lame.py
    no longer gives for them (a stale file) fail too."""
    import lame
    want, args = {}, None
    for line in open(expected):
        if line.startswith("# lame:"):
            args = [float(a) for a in line.split(":", 1)[1].split()]
        elif line.strip() and not line.startswith("#"):
            k, v, r = line.split()
            want[k] = (float(v), r)
    off, on = lame.loss_of_fit_rpm(args, False), lame.loss_of_fit_rpm(args, True)
    exact = {"loss_of_fit_rpm.off": off, "loss_of_fit_rpm.on": on, "shift_on_off": on / off - 1}
    run(exe, prm_off, outdir=out_off)
    run(exe, prm_on, outdir=out_on)
    key = "interface.fit.loss_of_fit_rpm"
    a, b = summary_value(out_off, key), summary_value(out_on, key)
    got = {"loss_of_fit_rpm.off": a, "loss_of_fit_rpm.on": b, "shift_on_off": b / a - 1}
    ok = set(want) == set(got)
    for k, (v, r) in want.items():
        if abs(exact[k] - v) > 1e-6 * abs(v):
            print(f"{k}: {expected} says {v}, lame.py {exact[k]:.10g}: stale file")
            ok = False
        g, w = os.path.join(out_on, k + ".got"), os.path.join(out_on, k + ".want")
        open(g, "w").write(f"{k} {got[k]:.10g}\n")
        open(w, "w").write(f"{k} {v}\n")
        status = numdiff(g, w, r, "0")
        print(f"{k}: {got[k]:.8g} vs {v} (rtol {r}):", "ok" if status == 0 else "FAILED")
        ok &= status == 0
    print("spin softening:", "ok" if ok else "FAILED")
    return 0 if ok else 1


# Absolute tolerance of each contact.csv column where a value may be zero
# (numbers are written with 8 significant digits; elsewhere RTOL applies).
# Counts, flags and names must be equal; a fraction or an asymmetry that
# moves by 1e-6 fails, and so does a pressure that moves by 1e-3 Pa where
# the other is zero (the fit's pressures are ~1e7 Pa).
CONTACT_ATOL = {
    "speed_rpm": 0, "closed_pairs": 0, "total_pairs": 0, "contact_fraction": 1e-9,
    "mean_pressure_Pa": 1e-3, "max_pressure_Pa": 1e-3, "constraint_error": 1e-11,
    "active_set_iterations": 0, "uzawa_iterations": 0, "factorizations": 0,
    "low_rank_updates": 0, "converged": 0, "first_opening_rpm": 1e-3,
    "loss_of_fit_rpm": 1e-3, "asymmetry": 1e-9,
}


def same_table(a, b, columns, rtol):
    """Rows of the CSV files A and B agree column by column: a number within
    RTOL relative or the column's CONTACT_ATOL absolute, a word exactly.
    COLUMNS: a list of names, or None for every column of A."""
    import csv
    rows = [list(csv.DictReader(open(f))) for f in (a, b)]
    names = columns or list(rows[0][0].keys() if rows[0] else [])
    bad = 0
    if len(rows[0]) != len(rows[1]):
        print(f"{a}: {len(rows[0])} rows, {b}: {len(rows[1])}: FAILED")
        return 1
    for i, (ra, rb) in enumerate(zip(*rows)):
        for n in names:
            x, y = ra.get(n), rb.get(n)
            try:
                fx, fy = float(x), float(y)
            except (TypeError, ValueError):
                if x != y:
                    print(f"row {i + 1} {n}: '{x}' vs '{y}': FAILED")
                    bad += 1
                continue
            if fx != fx or fy != fy:  # nan (no such speed yet): on both sides
                if not (fx != fx and fy != fy):
                    print(f"row {i + 1} {n}: {x} vs {y}: FAILED")
                    bad += 1
                continue
            atol = CONTACT_ATOL.get(n, 0)
            d = abs(fx - fy)
            if not (d <= atol or d <= float(rtol) * max(abs(fx), abs(fy))):
                print(f"row {i + 1} {n}: {x} vs {y} (difference {d:.3g}; "
                      f"tolerance {rtol} relative, {atol} absolute): FAILED")
                bad += 1
    print(f"{len(rows[0])} rows, columns {', '.join(names)}: "
          + ("agree" if not bad else f"{bad} values differ"))
    return 1 if bad else 0


def same_columns(exe, prm_a, out_a, prm_b, out_b, columns, rtol, sets_a=(), sets_b=()):
    """Run both cases; the COLUMNS (comma-separated) of their contact.csv must
    agree row by row within RTOL relative or each column's CONTACT_ATOL."""
    run(exe, case(prm_a, out_a, sets_a) if sets_a else prm_a, outdir=None if sets_a else out_a)
    run(exe, case(prm_b, out_b, sets_b) if sets_b else prm_b, outdir=None if sets_b else out_b)
    return same_table(os.path.join(out_a, "contact.csv"), os.path.join(out_b, "contact.csv"),
                      columns.split(","), rtol)


def path_steps(exe, prm, outdir, interface, *sets):
    """The exact contact path (Contact/Speed path = exact) with speed steps
    of 1,000, 500 and 100 r/min over 0..30,000: first opening, half-open and
    full opening identical to 1 r/min. Then the sampled path (the active set
    settled anew at each speed, no events) 1 r/min below and above each of
    them: fit closed / partly open, contact fraction >= 0.5 / < 0.5, pairs
    closed / none. SETS: --set arguments of every run."""
    keys = ("first_opening_rpm", "half_open_rpm", "loss_of_fit_rpm")
    found = {}
    for step in (1000, 500, 100):
        out = os.path.join(outdir, f"step_{step}")
        run(exe, case(prm, out, [*sets, "Speeds/Mode=range",
                                 "Speeds/Start=0", "Speeds/End=30000", f"Speeds/Step={step}",
                                 "Contact/Speed path=exact"]))
        found[step] = [summary_value(out, f"interface.{interface}.{k}") for k in keys]
        print(f"step {step} r/min: " + ", ".join(f"{k} {v:.3f}" for k, v in zip(keys, found[step])))
    bad = 0
    for step in (500, 100):
        for k, a, b in zip(keys, found[1000], found[step]):
            if not abs(a - b) <= 1.0:
                print(f"{k}: {b} with step {step} vs {a} with step 1000: FAILED")
                bad += 1
    first, half, full = found[1000]
    speeds = sorted({0.0, first - 1, first + 1, half - 1, half + 1, full - 1, full + 1})
    out = os.path.join(outdir, "sampled")
    run(exe, case(prm, out, [*sets, "Speeds/Mode=list",
                             "Speeds/List=" + ", ".join(f"{v:.3f}" for v in speeds),
                             "Contact/Speed path=sampled"]))
    import csv
    rows = {round(float(r["speed_rpm"]), 3): r
            for r in csv.DictReader(open(os.path.join(out, "contact.csv")))
            if r["interface"] == interface}
    def at(v):
        return rows[round(v, 3)]
    checks = [
        ("first opening", first, lambda r: int(r["closed_pairs"]) == int(r["total_pairs"])),
        ("half-open", half, lambda r: float(r["contact_fraction"]) >= 0.5),
        ("full opening", full, lambda r: int(r["closed_pairs"]) > 0),
    ]
    for name, v, before in checks:
        ok = before(at(v - 1)) and not before(at(v + 1))
        print(f"{name} {v:.3f} r/min: sampled at -1 r/min closed {at(v - 1)['closed_pairs']}, "
              f"fraction {at(v - 1)['contact_fraction']}; at +1 r/min closed "
              f"{at(v + 1)['closed_pairs']}, fraction {at(v + 1)['contact_fraction']}: "
              + ("ok" if ok else "FAILED"))
        bad += not ok
    return 1 if bad else 0


def slip_steps(exe, prm, outdir, interface, rtol, *sets):
    """The slip speed on the exact path does not depend on the speeds asked
    for: PRM (with --set SETS) run with the speeds 0 and 30,000 r/min only
    and with a dense list; the slip speed must lie inside the fit's opening
    band (so that the path's changes between two speeds are crossed) and
    agree within RTOL."""
    found = []
    for name, speeds in (("two", "0, 30000"),
                         ("dense", "0, 10000, 20000, 22000, 22500, 22700, 22800, 22850, 22900, 30000")):
        out = os.path.join(outdir, name)
        run(exe, case(prm, out, [*sets, "Speeds/Mode=list", "Speeds/List=" + speeds,
                                 "Contact/Speed path=exact"]))
        found.append([summary_value(out, f"interface.{interface}.{k}")
                      for k in ("slip_rpm", "first_opening_rpm", "loss_of_fit_rpm")])
        print(f"{name} speeds: slip, first opening, loss of fit {found[-1]}")
    (slip_a, first, full), (slip_b, _, _) = found
    inside = first < slip_a < full
    same = abs(slip_a / slip_b - 1) <= float(rtol)
    print("slip speed inside the opening band:", "ok" if inside else "FAILED")
    print(f"slip speed {slip_a} (2 speeds) vs {slip_b} (dense), rtol {rtol}:",
          "ok" if same else "FAILED")
    return 0 if inside and same else 1


def paths(exe, prm, outdir, columns, rtol, *sets):
    """PRM (with --set SETS) on the exact path and on the sampled path with a
    factorisation per active set: COLUMNS of contact.csv as in same_columns."""
    exact = [*sets, "Contact/Speed path=exact"]
    sampled = [*sets, "Contact/Speed path=sampled", "Contact/Low-rank update limit=0"]
    return same_columns(exe, prm, os.path.join(outdir, "exact"), prm,
                        os.path.join(outdir, "sampled"), columns, rtol, exact, sampled)


def valid(exe, prm):
    """--validate must accept PRM (exit code 0, 'valid.' in its output) and
    print what it prints for the same file without its UTF-8 byte order
    mark, if it has one (the mark must not change what is read)."""
    import tempfile
    r = subprocess.run([exe, "--validate", prm], capture_output=True, text=True)
    print(r.stdout[-2000:], r.stderr[-2000:])
    ok = r.returncode == 0 and "valid." in r.stdout
    print("accepted:", "ok" if ok else "FAILED")
    raw = open(prm, "rb").read()
    if raw.startswith(b"\xef\xbb\xbf"):
        # the copy sits among links to the files beside PRM (its geometry)
        scratch, here = tempfile.mkdtemp(), os.path.dirname(os.path.abspath(prm))
        for f in os.listdir(here):
            if os.path.isfile(os.path.join(here, f)) and f != os.path.basename(prm):
                os.symlink(os.path.join(here, f), os.path.join(scratch, f))
        plain = os.path.join(scratch, os.path.basename(prm))
        open(plain, "wb").write(raw[3:])
        p = subprocess.run([exe, "--validate", plain], capture_output=True, text=True,
                           cwd=os.path.dirname(os.path.abspath(prm)))
        same = p.returncode == r.returncode and p.stdout.replace(plain, prm) == r.stdout
        print("the same output without the byte order mark:", "ok" if same else "FAILED")
        if not same:
            print(p.stdout[-2000:], p.stderr[-2000:])
        ok &= same
    return 0 if ok else 1


def static_flags(exe, prm, outdir, text, limit=None):
    """A static state that is not converged must say so everywhere: the run
    ends with exit code 0, every row of contact.csv with closed pairs has
    converged = 0 and TEXT in its status (with LIMIT only the rows whose
    constraint error exceeds it; a row without closed pairs is not judged),
    every row of campbell.csv at those speeds has
    static_converged = 0, summary.txt counts those speeds and the log warns."""
    import csv
    run(exe, prm, outdir=outdir)
    ok = True
    rows = list(csv.DictReader(open(os.path.join(outdir, "contact.csv"))))
    flagged = set()
    for r in rows:
        print(r["speed_rpm"], r["closed_pairs"], r["converged"], r["status"])
        # with LIMIT: flagged exactly where the constraint error exceeds it
        if int(r["closed_pairs"]) > 0 and (limit is None or
                                           float(r["constraint_error"]) > float(limit)):
            ok &= r["converged"] == "0" and text in r["status"]
            flagged.add(r["speed_rpm"])
        elif int(r["closed_pairs"]) > 0:
            ok &= r["converged"] == "1" and r["status"] == "ok"
        elif r["converged"] == "0":
            flagged.add(r["speed_rpm"])
    ok &= len(flagged) > 0
    campbell = os.path.join(outdir, "campbell.csv")
    if os.path.isfile(campbell):
        modes = list(csv.DictReader(open(campbell)))
        print(f"campbell.csv: {len(modes)} rows, static_converged",
              sorted({(m["speed_rpm"], m["static_converged"]) for m in modes}))
        ok &= len(modes) > 0 and all((m["static_converged"] == "0") == (m["speed_rpm"] in flagged)
                                     for m in modes)
    ok &= summary_value(outdir, "static.unconverged_speeds") == len(flagged)
    log = open(os.path.join(outdir, "log.txt")).read()
    ok &= "is not converged" in log or "exceeds its limit" in log
    print("unconverged static state flagged:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def lock_and_signal(exe, prm, outdir):
    """Two runs into one folder and a SIGTERM. Run A starts; run B into the
    same folder is refused (exit code 1) naming A's process id; A receives
    SIGTERM once it has finished a speed, stops with exit code 3, its log
    says where it stopped, summary.txt says 'interrupted', and every row it
    wrote to campbell.csv is complete."""
    import csv
    import signal
    import time
    args = case(prm, outdir)
    log = os.path.join(outdir, "campbell.csv")
    if os.path.exists(log):
        os.remove(log)
    a = subprocess.Popen([exe] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 300
    while time.time() < deadline and a.poll() is None:
        if os.path.exists(log) and len(open(log).read().splitlines()) >= 2:
            break
        time.sleep(0.2)
    # A is held (SIGSTOP) while B tries the folder: a fast A could
    # otherwise finish its sweep before B is refused and the SIGTERM sent
    # (seen once under ctest -j2); the SIGTERM waits for SIGCONT
    a.send_signal(signal.SIGSTOP)
    b = subprocess.run([exe] + args, capture_output=True, text=True)
    print("second run:", b.returncode, b.stderr.strip())
    ok = b.returncode == 1 and f"process id {a.pid})" in b.stderr
    a.send_signal(signal.SIGTERM)
    a.send_signal(signal.SIGCONT)
    out, err = a.communicate(timeout=600)
    print(out[-1500:], err[-1500:])
    print("first run exit code:", a.returncode, "(expected 3)")
    ok &= a.returncode == 3
    text = open(os.path.join(outdir, "log.txt")).read()
    ok &= "interrupted by SIGTERM" in text and "speeds finished" in text
    summary = open(os.path.join(outdir, "summary.txt")).read()
    ok &= "run.status interrupted" in summary
    table = list(csv.reader(open(log, newline="")))
    rows = table[1:]
    ok &= len(rows) >= 1 and all(len(r) == len(table[0]) for r in rows)
    print(f"campbell.csv: {len(rows)} complete rows")
    print("lock and signal:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def check_areas(stdout, lines):
    """The areas --validate printed (STDOUT) for interfaces and bearings
    against LINES 'area.NAME value rtol' (mm^2, closed forms)."""
    found = {m.group(1): float(m.group(2)) for m in
             re.finditer(r"(?:Interface|bearing) (\S+?):? .*?area ([0-9.eE+-]+) mm\^2", stdout)}
    ok = True
    for line in lines:
        key, want, rtol = line.split()
        got = found.get(key[len("area."):])
        good = got is not None and abs(got - float(want)) <= float(rtol) * abs(float(want))
        print(f"{key}: {got} vs {want} mm^2 (error "
              f"{'-' if got is None else f'{(got - float(want)) / float(want):+.2e}'}, rtol {rtol}):",
              "ok" if good else "FAILED")
        ok &= good
    return ok


def expected_lines(path):
    return [l.rstrip("\n") for l in open(path) if l.strip() and not l.startswith("#")]


def areas(exe, prm, expected):
    """--validate accepts PRM, and the areas it reports for interfaces and
    bearings (mm^2) match the file EXPECTED ('area.NAME value rtol' per line,
    closed forms named in its comments): a mesh or a physical group that is
    wrong cannot pass."""
    r = subprocess.run([exe, "--validate", prm], capture_output=True, text=True)
    print(r.stdout[-3000:], r.stderr[-2000:])
    ok = r.returncode == 0 and "valid." in r.stdout
    return 0 if check_areas(r.stdout, expected_lines(expected)) and ok else 1


def prints(exe, prm, expected, *options):
    """--validate [OPTIONS] PRM is accepted and prints every line of
    EXPECTED (after its '#' comments) within its output lines, in order;
    lines 'area.NAME value rtol' are areas against closed forms (areas())."""
    r = subprocess.run([exe, "--validate"] + list(options) + [prm], capture_output=True, text=True)
    out = r.stdout.splitlines()
    ok, at = r.returncode == 0, 0
    lines = expected_lines(expected)
    for want in (l for l in lines if not l.startswith("area.")):
        found = next((i for i in range(at, len(out)) if want in out[i]), None)
        print(("found:   " if found is not None else "MISSING: ") + want)
        ok &= found is not None
        at = found if found is not None else at  # the next part may be on the same line
    ok &= check_areas(r.stdout, [l for l in lines if l.startswith("area.")])
    if not ok:
        print(r.stdout[-3000:], r.stderr[-2000:])
    return 0 if ok else 1


def parameters_doc(generated, doc):
    """DOC (doc/parameters.md) must be exactly GENERATED, which the build
    writes from `rotorfit --print-parameters json`: the parameter reference
    cannot drift from the code."""
    import difflib
    got, want = open(generated).read(), open(doc).read()
    if got == want:
        print(f"{doc} matches the declared parameters: ok")
        return 0
    sys.stdout.writelines(difflib.unified_diff(want.splitlines(True), got.splitlines(True),
                                               doc, generated))
    print(f"{doc} is out of date: 'cmake --build build --target update_parameters_doc' "
          "copies the generated one")
    return 1


def version(exe, source_dir):
    """`rotorfit --version` must name the commit of the source tree it was
    built from, as git describes it now (-dirty for uncommitted changes):
    a binary built before a commit or an edit fails here (rebuild it)."""
    got = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout
    m = re.search(r"\(git ([^,]+),", got)
    if not m:
        sys.exit(f"no '(git HASH,' in the version line: {got!r}")
    try:
        r = subprocess.run(["git", "-C", source_dir, "describe", "--always", "--dirty", "--abbrev=7",
                            "--match=rotorfit-no-such-tag"], capture_output=True, text=True)
        want = r.stdout.strip() if r.returncode == 0 and r.stdout.strip() else "unknown"
    except OSError:  # no git on the machine: the build said "unknown" too
        want = "unknown"
    if m.group(1) != want:
        print(f"the binary names {m.group(1)}, the source tree is {want}: rebuild")
        return 1
    print(f"the binary names the source tree's commit {want}: ok")
    return 0


def error(exe, prm, expected, *options):
    """--validate [OPTIONS] PRM must refuse the input (exit code 1) with
    exactly the message EXPECTED (numbers to 1e-6 relative)."""
    import tempfile
    r = subprocess.run([exe, "--validate"] + list(options) + [prm], capture_output=True, text=True)
    got = os.path.join(tempfile.mkdtemp(), os.path.basename(expected) + ".got")
    open(got, "w").write(r.stderr)
    if r.returncode != 1:
        print(r.stdout, r.stderr)
        sys.exit(f"expected exit code 1, got {r.returncode}")
    if "Stacktrace" in r.stderr or "-------" in r.stderr:
        sys.exit("the error message carries a stack trace")
    return numdiff(got, expected, 1e-6, 1e-12)


def csv_fields(exe, prm, outdir, text):
    """Run PRM into OUTDIR: every row of every CSV file it wrote has as many
    fields as its header (csv module, RFC 4180 quoting), and a status of
    contact.csv holds TEXT with a comma in it (a field that must be quoted)."""
    import csv
    import glob
    run(exe, prm, outdir=outdir)
    ok = True
    for path in sorted(glob.glob(os.path.join(outdir, "*.csv"))):
        table = list(csv.reader(open(path, newline="")))
        bad = [i + 1 for i, r in enumerate(table[1:], 1) if len(r) != len(table[0])]
        print(f"{os.path.basename(path)}: {len(table) - 1} rows of {len(table[0])} fields:",
              "ok" if not bad else f"FAILED at lines {bad[:5]}")
        ok &= not bad
    status = [r["status"] for r in csv.DictReader(open(os.path.join(outdir, "contact.csv"),
                                                       newline=""))]
    found = any(text in s and "," in s for s in status)
    print(f"a status with '{text}' and a comma:", "ok" if found else f"FAILED {status}")
    return 0 if ok and found else 1


def locked(exe, prm, outdir):
    """--validate --output OUTDIR PRM while this process holds OUTDIR's lock
    (as a running rotorfit does): refused with exit code 1, naming this
    process id, and the lock file left as it was."""
    import fcntl
    os.makedirs(outdir, exist_ok=True)
    with open(os.path.join(outdir, ".rotorfit.lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        lock.write(f"{os.getpid()}\n")
        lock.flush()
        r = subprocess.run([exe, "--validate", "--output", outdir, prm], capture_output=True,
                           text=True)
    print(r.returncode, r.stdout[-1500:], r.stderr)
    want = f"Output/Directory = '{outdir}' is in use by another rotorfit run (process id {os.getpid()})"
    ok = r.returncode == 1 and want in r.stderr
    print("--validate refuses a folder another run holds:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def plot_warning(exe, prm_latin1, prm, outdir):
    """The run's warning about a picture gives the script's own error: a
    Latin-1 case (PRM_LATIN1) makes plot_contact.py fail to decode its CSV
    file, and the warning names UnicodeDecodeError without blaming
    matplotlib; PRM with a matplotlib that cannot be imported (a stand-in
    on PYTHONPATH) blames python3-matplotlib. Both runs end with exit code 0."""
    import tempfile
    fake = tempfile.mkdtemp()
    os.makedirs(os.path.join(fake, "matplotlib"))
    open(os.path.join(fake, "matplotlib", "__init__.py"), "w").write(
        "raise ImportError(\"No module named 'matplotlib' (a stand-in of the test)\")\n")
    ok = True
    for case, env, want, unwanted in (
            (prm_latin1, {}, "plot_contact.py failed: UnicodeDecodeError", "matplotlib"),
            (prm, {"PYTHONPATH": fake}, "python3-matplotlib", None)):
        out = os.path.join(outdir, os.path.splitext(os.path.basename(case))[0])
        r = subprocess.run([exe, "--output", out, case], capture_output=True, text=True,
                           errors="replace", env=dict(os.environ, **env))
        lines = [l for l in r.stdout.splitlines() if "contact.png could not be drawn" in l]
        print(f"{case}: exit code {r.returncode}; {lines}")
        good = (r.returncode == 0 and len(lines) == 1 and want in lines[0] and
                (unwanted is None or unwanted not in lines[0]))
        if not good:
            print(r.stdout[-3000:], r.stderr[-2000:])
        print(f"warning with '{want}'" + (f", without '{unwanted}'" if unwanted else "") + ":",
              "ok" if good else "FAILED")
        ok &= good
    return 0 if ok else 1


if __name__ == "__main__":
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "compare":
        sys.exit(compare(*args))
    elif mode == "error":
        sys.exit(error(*args))
    elif mode == "prints":
        sys.exit(prints(*args))
    elif mode == "version":
        sys.exit(version(*args))
    elif mode == "parameters_doc":
        sys.exit(parameters_doc(*args))
    elif mode == "areas":
        sys.exit(areas(*args))
    elif mode == "valid":
        sys.exit(valid(*args))
    elif mode == "static_flags":
        sys.exit(static_flags(*args))
    elif mode == "lock_and_signal":
        sys.exit(lock_and_signal(*args))
    elif mode == "csv_fields":
        sys.exit(csv_fields(*args))
    elif mode == "locked":
        sys.exit(locked(*args))
    elif mode == "plot_warning":
        sys.exit(plot_warning(*args))
    elif mode == "pictures":
        sys.exit(pictures(*args))
    elif mode == "falls":
        sys.exit(falls(*args))
    elif mode == "softening":
        sys.exit(softening(*args))
    elif mode == "slip_steps":
        sys.exit(slip_steps(*args))
    elif mode == "paths":
        sys.exit(paths(*args))
    elif mode == "path_steps":
        sys.exit(path_steps(*args))
    elif mode == "same_columns":
        sys.exit(same_columns(*args))
    elif mode == "ratio":
        sys.exit(ratio(*args))
    elif mode == "same":
        exe, prm, out1, out2, rtol = args
        run(exe, prm, 1, out1)
        run(exe, prm, 2, out2)
        sys.exit(same_table(os.path.join(out1, "contact.csv"), os.path.join(out2, "contact.csv"),
                            None, rtol))
    sys.exit(f"unknown mode {mode}")
