#!/usr/bin/env python3
"""compare_results.py A B: byte-compare every result file under output folder A with the same file
under B, to show that a change of the code leaves the results as they were.
csv files byte for byte; summary.txt and other .txt files after dropping lines that carry
timings, memory, dates, versions or paths (these differ run to run). log.txt, pictures,
ParaView files, meshes and parameters.prm are skipped. Prints each difference; exit 1 if any."""
import os, re, sys
A, B = sys.argv[1], sys.argv[2]
VOLATILE = re.compile(r'(peak_memory|memory_gb|seconds|\btime\b|_time|wall|version|\bgit\b|/work/|/tmp/|elapsed|\bdate\b)', re.I)
bad = n = 0
for root, _, files in os.walk(A):
    for f in sorted(files):
        pa = os.path.join(root, f); rel = os.path.relpath(pa, A); pb = os.path.join(B, rel)
        if f == 'log.txt' or f.endswith(('.png', '.vtu', '.pvtu', '.pvd', '.msh', '.prm', '.inp', '.dat', '.frd', '.sta', '.cvg', '.12d')):
            continue
        if not (f.endswith('.csv') or f.endswith('.txt') or f.endswith('.json')):
            continue
        n += 1
        if not os.path.exists(pb):
            print('missing in B:', rel); bad += 1; continue
        a = open(pa, 'rb').read(); b = open(pb, 'rb').read()
        if f.endswith('.csv') or f.endswith('.json'):
            if a != b:
                print('differs:', rel); bad += 1
        else:
            fa = [l for l in a.decode('utf8', 'replace').splitlines() if not VOLATILE.search(l)]
            fb = [l for l in b.decode('utf8', 'replace').splitlines() if not VOLATILE.search(l)]
            if fa != fb:
                bad += 1
                print('differs:', rel)
                for x, y in zip(fa, fb):
                    if x != y:
                        print('  A:', x); print('  B:', y); break
print(f'{n} files compared, {bad} differ')
sys.exit(1 if bad else 0)
