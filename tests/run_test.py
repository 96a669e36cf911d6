#!/usr/bin/env python3
"""CTest driver for rotorfit. Every check compares numbers against analytic or
independently known values at a tolerance stated in tests/CMakeLists.txt.

  run_test.py compare EXE PRM OUTDIR EXPECTED RTOL ATOL [NP]
      run the case, take the keys of EXPECTED from OUTDIR/summary.txt and
      compare them with numdiff (relative RTOL, absolute ATOL).
  run_test.py error EXE PRM EXPECTED
      --validate must fail with exit code 1; stderr is compared with EXPECTED
      (numdiff, numbers to 1e-6 relative).
  run_test.py same EXE PRM OUTDIR_1 OUTDIR_2 RTOL ATOL
      contact.csv with 1 and 2 MPI ranks must agree (numdiff).
"""
import os
import subprocess
import sys


def numdiff(a, b, rtol, atol):
    r = subprocess.run(["numdiff", "-q", "-r", str(rtol), "-a", str(atol), a, b])
    if r.returncode != 0:
        subprocess.run(["numdiff", "-r", str(rtol), "-a", str(atol), a, b])
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
    """A copy of PRM next to it whose Output/Directory is OUTDIR."""
    text = open(prm).read()
    import re
    text = re.sub(r"(subsection Output.*?set Directory\s*=\s*)\S+", r"\g<1>" + outdir, text,
                  flags=re.S)
    copy = os.path.join(os.path.dirname(os.path.abspath(prm)),
                        "." + os.path.basename(outdir) + ".prm")
    open(copy, "w").write(text)
    return copy


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


def error(exe, prm, expected):
    r = subprocess.run([exe, "--validate", prm], capture_output=True, text=True)
    got = os.path.basename(expected) + ".got"
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
    elif mode == "same":
        exe, prm, out1, out2, rtol, atol = args
        run(exe, set_output(prm, out1), 1)
        run(exe, set_output(prm, out2), 2)
        sys.exit(numdiff(os.path.join(out1, "contact.csv"), os.path.join(out2, "contact.csv"),
                         rtol, atol))
    sys.exit(f"unknown mode {mode}")
