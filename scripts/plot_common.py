"""What the picture scripts of a rotorfit output folder share: reading its CSV files and
summary.txt, and the label layout (label_layout.py, imported only when a picture is drawn, so
that a missing matplotlib/numpy is reported by the caller)."""
import csv
import math
import os


def read_csv(path):
    """Rows of a CSV file as dicts (empty list if the file is missing or has no data rows)."""
    if not os.path.isfile(path):
        return []
    with open(path, newline="") as f:
        return [{k.strip(): (v or "").strip() for k, v in r.items() if k} for r in csv.DictReader(f)]


def num(s, default=None):
    """Float of a CSV field ('2X' reads 2); default for empty, malformed, nan and inf."""
    try:
        v = float(s.rstrip("xX"))
        return v if math.isfinite(v) else default
    except (AttributeError, TypeError, ValueError):
        return default


def summary_values(path):
    """{key: value text} of summary.txt (empty if missing)."""
    out = {}
    if os.path.isfile(path):
        with open(path) as f:
            for line in f:
                p = line.split(None, 1)
                if len(p) == 2:
                    out[p[0]] = p[1].strip()
    return out


def layout_module():
    """label_layout.py (next to this file; needs numpy and matplotlib)."""
    import label_layout
    return label_layout


def labels_ok(fig, texts):
    """True if the drawn boxes of texts neither overlap nor leave their axes / the figure
    (problems on stderr)."""
    return layout_module().labels_ok(fig, texts)
