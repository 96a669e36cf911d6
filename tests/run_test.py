#!/usr/bin/env python3
"""CTest driver for rotorfit. Every check compares numbers against analytic or
independently known values at a tolerance stated in tests/CMakeLists.txt.

  run_test.py compare EXE PRM OUTDIR EXPECTED RTOL ATOL [NP]
      run the case, take the keys of EXPECTED from OUTDIR/summary.txt and
      compare them with numdiff (relative RTOL, absolute ATOL).
  run_test.py error EXE PRM EXPECTED
      --validate must fail with exit code 1; stderr is compared with EXPECTED
      (numdiff, numbers to 1e-6 relative).
  run_test.py ratio EXE PRM_A OUT_A PRM_B OUT_B KEY EXPECTED RTOL
      run two cases; KEY(A)/KEY(B) must equal EXPECTED within RTOL (numdiff).
  run_test.py same EXE PRM OUTDIR_1 OUTDIR_2 RTOL ATOL
      contact.csv with 1 and 2 MPI ranks must agree (numdiff).
"""
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


def run(exe, prm, np=1):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    cmd = [exe, prm] if np == 1 else ["mpirun", "-np", str(np), exe, prm]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    sys.stdout.write(r.stdout[-3000:])
    sys.stderr.write(r.stderr[-3000:])
    if r.returncode != 0:
        sys.exit(f"rotorfit exited with {r.returncode}")


def set_output(prm, outdir):
    """A copy of PRM in the working directory writing to OUTDIR, with the
    geometry file made absolute."""
    import re
    text = open(prm).read()
    text = re.sub(r"(subsection Output.*?set Directory\s*=\s*)\S+", r"\g<1>" + outdir, text,
                  flags=re.S)
    base = os.path.dirname(os.path.abspath(prm))
    text = re.sub(r"(set Geometry file\s*=\s*)(\S+)",
                  lambda m: m.group(1) + os.path.normpath(os.path.join(base, m.group(2))), text)
    copy = os.path.basename(outdir) + ".prm"
    open(copy, "w").write(text)
    return copy


def falls(exe, prm, outdir):
    """Contact fraction of every interface: 1 at the first speed, then
    strictly decreasing once below 1, and still > 0 (partial opening)."""
    run(exe, prm)
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
    print("contact fraction falls with speed:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def compare(exe, prm, outdir, expected, rtol, atol, np="1"):
    run(exe, prm, int(np))
    summary = dict(l.split(None, 1) for l in open(os.path.join(outdir, "summary.txt")) if l.strip())
    # each line: key value [rtol atol]; a line's own tolerances override
    failed = 0
    for line in open(expected):
        if not line.strip() or line.startswith("#"):
            continue
        f = line.split()
        key, value = f[0], f[1]
        r, a = (f[2], f[3]) if len(f) >= 4 else (rtol, atol)
        if key not in summary:
            sys.exit(f"{key} missing from summary.txt")
        got, want = (os.path.join(outdir, key + s) for s in (".got", ".want"))
        open(got, "w").write(f"{key} {summary[key].strip()}\n")
        open(want, "w").write(f"{key} {value}\n")
        status = numdiff(got, want, r, a)
        print(f"{key}: {summary[key].strip()} vs {value} (rtol {r}, atol {a}):",
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
    run(exe, prm_a)
    run(exe, prm_b)
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


def softening(exe, prm_off, out_off, prm_on, out_on, lame_args, rtol, shift_rtol):
    """Plane-strain fit with spin softening off and on: each loss of fit
    within RTOL of its exact value (tests/lame.py), and the shift
    on/off - 1 within SHIFT_RTOL of the exact shift (same mesh, so the
    discretisation error of the speed itself cancels)."""
    import lame
    args = [float(a) for a in lame_args.split(",")]
    exact = {False: lame.loss_of_fit_rpm(args, False), True: lame.loss_of_fit_rpm(args, True)}
    run(exe, prm_off)
    run(exe, prm_on)
    key = "interface.fit.loss_of_fit_rpm"
    got = {False: summary_value(out_off, key), True: summary_value(out_on, key)}
    ok = True
    for s in (False, True):
        e = got[s] / exact[s] - 1
        print(f"spin softening {'on' if s else 'off'}: loss of fit {got[s]:.8g} vs {exact[s]:.8g} r/min "
              f"({e:+.2e}, rtol {rtol})")
        ok &= abs(e) <= float(rtol)
    shift, shift_exact = got[True] / got[False] - 1, exact[True] / exact[False] - 1
    e = shift / shift_exact - 1
    print(f"shift on/off - 1: {shift:.5e} vs {shift_exact:.5e} ({e:+.2e}, rtol {shift_rtol})")
    ok &= abs(e) <= float(shift_rtol)
    print("spin softening:", "ok" if ok else "FAILED")
    return 0 if ok else 1


def same_columns(exe, prm_a, out_a, prm_b, out_b, columns, rtol, atol):
    """Run both cases; the COLUMNS (comma-separated) of their contact.csv must
    agree within RTOL/ATOL row by row (numdiff)."""
    import csv
    run(exe, set_output(prm_a, out_a))
    run(exe, set_output(prm_b, out_b))
    names = columns.split(",")
    files = []
    for out in (out_a, out_b):
        rows = list(csv.DictReader(open(os.path.join(out, "contact.csv"))))
        path = os.path.join(out, "contact_columns.txt")
        with open(path, "w") as f:
            for r in rows:
                f.write(" ".join(r[n] for n in names) + "\n")
        files.append(path)
        print(out, "rows:", len(rows))
    return numdiff(files[0], files[1], rtol, atol)


def error(exe, prm, expected):
    import tempfile
    r = subprocess.run([exe, "--validate", prm], capture_output=True, text=True)
    got = os.path.join(tempfile.mkdtemp(), os.path.basename(expected) + ".got")
    open(got, "w").write(r.stderr)
    if r.returncode != 1:
        print(r.stdout, r.stderr)
        sys.exit(f"expected exit code 1, got {r.returncode}")
    if "Stacktrace" in r.stderr or "-------" in r.stderr:
        sys.exit("the error message carries a stack trace")
    return numdiff(got, expected, 1e-6, 1e-12)


if __name__ == "__main__":
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "compare":
        sys.exit(compare(*args))
    elif mode == "error":
        sys.exit(error(*args))
    elif mode == "falls":
        sys.exit(falls(*args))
    elif mode == "softening":
        sys.exit(softening(*args))
    elif mode == "same_columns":
        sys.exit(same_columns(*args))
    elif mode == "ratio":
        sys.exit(ratio(*args))
    elif mode == "same":
        exe, prm, out1, out2, rtol, atol = args
        run(exe, set_output(prm, out1), 1)
        run(exe, set_output(prm, out2), 2)
        sys.exit(numdiff(os.path.join(out1, "contact.csv"), os.path.join(out2, "contact.csv"),
                         rtol, atol))
    sys.exit(f"unknown mode {mode}")
