#!/usr/bin/env python3
"""Label placement shared by the plot_*.py scripts (imported by them; run on its own it checks itself).

LabelLayout(ax).place(items) puts short horizontal labels next to their anchor points so that no
two labels overlap and none leaves the axes frame. It works in display coordinates after the
figure's layout is final (axis limits set, tight_layout done; the figure is saved at its own dpi):
every label is measured with the renderer (text plus its background box), the labels are taken in
order of their anchor's x and each one gets the cheapest free spot among
  - the spots next to the anchor (right of, left of or centred on it; above or below it; right
    and left also level with it), then the same stacked one, two, ... label heights further up or
    down (sort by x, stack vertically),
  - a grid over the whole frame (far fallback),
each shifted into the frame. Cost: stacking level + distance, a small penalty for the
non-preferred side, a large one for covering a fixed text (obstacle) or another anchor's marker,
a small one per point of a curve covered (`avoid`, sampled every 4 px; at most 3 levels' worth),
and an overwhelming one for touching a label already placed. A label away from its anchor gets a
thin leader line. The chosen offset is fixed in points relative to the anchor (offset_copy), so it
survives savefig at the figure's dpi.

labels_ok(fig, texts) draws the figure and checks the real renderer boxes
(text.get_window_extent() and its background patch): no two overlap and each lies inside its axes
and the figure; problems are listed on stderr.

Usage: label_layout.py [--self-test OUT.png]   (a crowded fake case; exit 1 if the check fails)
"""
import argparse
import math
import sys

import numpy as np


def _box_of(text, renderer):
    """(x0, y0, x1, y1) of a text with its background patch, display coordinates."""
    bb = text.get_window_extent(renderer)
    boxes = [(bb.x0, bb.y0, bb.x1, bb.y1)]
    patch = text.get_bbox_patch()
    if patch is not None:
        pb = patch.get_window_extent(renderer)
        boxes.append((pb.x0, pb.y0, pb.x1, pb.y1))
    return (min(b[0] for b in boxes), min(b[1] for b in boxes),
            max(b[2] for b in boxes), max(b[3] for b in boxes))


def _overlap(a, b, tol=0.0):
    """Overlap area of two (x0, y0, x1, y1) boxes (0 if they only touch or are within tol)."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > tol and h > tol else 0.0


def labels_ok(fig, texts, tol=0.5, out=sys.stderr):
    """True if no two of texts overlap and each lies inside its axes and the figure.

    Uses the renderer's boxes of the drawn figure (text extent plus background patch);
    tol [px] forgives rounding. Invisible or empty texts are ignored."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    fb = fig.bbox
    shown = [t for t in texts if t is not None and t.get_visible() and t.get_text().strip()]
    boxes, ok = [], True
    for t in shown:
        b = _box_of(t, renderer)
        boxes.append(b)
        frames = [("figure", (fb.x0, fb.y0, fb.x1, fb.y1))]
        if t.axes is not None:
            ab = t.axes.bbox
            frames.append(("axes", (ab.x0, ab.y0, ab.x1, ab.y1)))
        for name, f in frames:
            if b[0] < f[0] - tol or b[1] < f[1] - tol or b[2] > f[2] + tol or b[3] > f[3] + tol:
                print(f"label {t.get_text()!r} leaves the {name} "
                      f"(box {tuple(round(v, 1) for v in b)}, frame {tuple(round(v, 1) for v in f)})", file=out)
                ok = False
    for i in range(len(shown)):
        for j in range(i + 1, len(shown)):
            if _overlap(boxes[i], boxes[j], tol) > 0:
                print(f"labels {shown[i].get_text()!r} and {shown[j].get_text()!r} overlap", file=out)
                ok = False
    return ok


class LabelLayout:
    """Collision-avoiding placement of labels in one axes (see the module docstring).

    ax: the axes; avoid: optional list of polylines, each (N, 2) data points (ax.transData) that
    labels should rather not cover (curves); margin: free space kept around each label [px]."""

    def __init__(self, ax, avoid=None, margin=2.0):
        self.ax = ax
        self.fig = ax.figure
        self.fig.canvas.draw()            # final limits (equal aspect, autoscale) and layout
        self.renderer = self.fig.canvas.get_renderer()
        self.margin = margin
        self.hard = []                    # boxes of labels placed (never overlap these)
        self.soft = []                    # boxes of fixed texts (rather not)
        self.markers = []                 # (owner, box) of anchor markers (rather not cover)
        self.avoid = np.empty((0, 2))
        for curve in avoid or []:
            self.add_avoid(curve, line=True)
        ab = ax.bbox
        self.frame = (ab.x0 + 1, ab.y0 + 1, ab.x1 - 1, ab.y1 - 1)

    def add_avoid(self, points, transform=None, line=False):
        """More data points (in transform, default ax.transData) labels should rather not cover;
        line=True: a polyline, sampled every 4 px between its points (a nan point breaks it);
        non-finite points (nan, log of 0) are ignored."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        if not len(pts):
            return
        with np.errstate(all="ignore"):
            disp = (transform or self.ax.transData).transform(pts)
        finite = np.all(np.isfinite(disp), axis=1)
        out = [disp[finite]]
        if line:
            for a, b, ok in zip(disp, disp[1:], finite[:-1] & finite[1:]):
                n = int(np.hypot(*(b - a)) // 4) if ok else 0
                if n > 1:
                    t = np.linspace(0, 1, n + 1)[1:-1, None]
                    out.append(a + t * (b - a))
        self.avoid = np.vstack([self.avoid] + out)

    def px(self, points):
        return points * self.fig.dpi / 72.0

    def add_text(self, text, hard=True):
        """Count an existing text (e.g. an info box) as taken space."""
        self.fig.canvas.draw()
        (self.hard if hard else self.soft).append(_box_of(text, self.renderer))

    def add_marker(self, xy, transform=None, radius_pt=5.0, owner=None):
        """A marker labels should not cover (soft); xy in transform (default ax.transData)."""
        p = (transform or self.ax.transData).transform(xy)
        r = self.px(radius_pt)
        if np.all(np.isfinite(p)):
            self.markers.append((owner, (p[0] - r, p[1] - r, p[0] + r, p[1] + r)))

    def _candidates(self, p, w, h, prefer, near_only):
        d, s = self.px(4.0), h + self.px(1.5)
        px_, py_ = p
        sides = {"right": px_ + d, "left": px_ - d - w, "center": px_ - w / 2}
        out = []
        for k in range(1 if near_only else 25):
            for hs, x0 in sides.items():
                for vs in ("up", "down", "mid"):
                    if vs == "mid" and (k > 0 or hs == "center"):
                        continue
                    y0 = {"up": py_ + d + k * s, "down": py_ - d - h - k * s, "mid": py_ - h / 2}[vs]
                    cost = k + (0 if hs == prefer[0] else 0.3 if hs == "center" else 0.6) \
                        + (0 if vs == prefer[1] else 0.4)
                    out.append((cost, x0, y0))
        if not near_only:                 # anywhere in the frame, by distance
            f = self.frame
            for x0 in np.arange(f[0], f[2] - w + 1e-9, max(w / 3, 4.0)):
                for y0 in np.arange(f[1], f[3] - h + 1e-9, max(s / 2, 4.0)):
                    dist = math.hypot(x0 + w / 2 - px_, y0 + h / 2 - py_)
                    out.append((3 + dist / s, x0, y0))
        return out

    def place(self, items, fontsize=8, leader=True, near_only=False, box=True):
        """Place labels; items: dicts with x, y (anchor in `transform`, default ax.transData),
        text, optional prefer=(right|left|center, up|down|mid), color, transform.
        Returns the Text artists in the order of items (None for a non-finite anchor)."""
        from matplotlib.transforms import offset_copy
        ax, fig = self.ax, self.fig
        texts = [None] * len(items)
        order = []
        for i, it in enumerate(items):
            tr = it.get("transform", ax.transData)
            try:
                p = tr.transform((it["x"], it["y"]))
            except (TypeError, ValueError):
                continue
            if np.all(np.isfinite(p)):
                order.append((p[0], p[1], i, p, tr))
        batch = object()
        for *_, i, p, tr in order:
            r = self.px(5.0)
            self.markers.append(((batch, i), (p[0] - r, p[1] - r, p[0] + r, p[1] + r)))
        m = self.margin
        f = self.frame
        for *_, i, p, tr in sorted(order, key=lambda o: (o[0], o[1])):
            it = items[i]
            t = ax.text(it["x"], it["y"], it["text"], transform=tr, fontsize=fontsize, ha="left", va="bottom",
                        color=it.get("color", "black"), zorder=6, clip_on=False,
                        bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.85) if box else None)
            bb = t.get_window_extent(self.renderer)
            pad = self.px(0.2 * fontsize) if box else 0.0
            w, h = bb.width + 2 * pad, bb.height + 2 * pad
            prefer = it.get("prefer", ("right", "up"))
            best = None
            for cost, x0, y0 in self._candidates(p, w, h, prefer, near_only):
                x0 = min(max(x0, f[0]), max(f[0], f[2] - w))      # shift into the frame
                y0 = min(max(y0, f[1]), max(f[1], f[3] - h))
                cand = (x0 - m, y0 - m, x0 + w + m, y0 + h + m)
                if best is not None and cost >= best[0]:
                    continue
                cost += 1e6 * sum(_overlap(cand, b) > 0 for b in self.hard)
                if best is not None and cost >= best[0]:
                    continue
                cost += 50 * sum(_overlap(cand, b) > 0 for b in self.soft)
                cost += 50 * sum(_overlap(cand, b) > 0 for key, b in self.markers if key != (batch, i))
                if len(self.avoid):
                    a = self.avoid
                    inside = (a[:, 0] > cand[0]) & (a[:, 0] < cand[2]) & (a[:, 1] > cand[1]) & (a[:, 1] < cand[3])
                    cost += 0.1 * min(int(inside.sum()), 30)
                if best is None or cost < best[0]:
                    best = (cost, x0, y0)
            if best is None:
                t.remove()
                continue
            if best[0] >= 1e6:
                print(f"label_layout: no free place for {it['text']!r}", file=sys.stderr)
            _, x0, y0 = best
            dx, dy = x0 + pad - p[0], y0 + pad - p[1]
            k = 72.0 / fig.dpi
            t.set_transform(offset_copy(tr, fig=fig, x=dx * k, y=dy * k, units="points"))
            self.hard.append((x0, y0, x0 + w, y0 + h))
            texts[i] = t
            # leader line from the anchor to the nearest point of the box if the label is not adjacent
            qx, qy = min(max(p[0], x0), x0 + w), min(max(p[1], y0), y0 + h)
            if leader and math.hypot(qx - p[0], qy - p[1]) > self.px(6.5):
                ax.annotate("", xy=(it["x"], it["y"]), xycoords=tr,
                            xytext=((qx - p[0]) * k, (qy - p[1]) * k), textcoords="offset points",
                            arrowprops=dict(arrowstyle="-", color=it.get("color", "0.35"), lw=0.6,
                                            shrinkA=0, shrinkB=3, alpha=0.8), zorder=5)
        return texts


def _self_test(png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5), dpi=150)
    rng = np.random.default_rng(1)
    xs = np.concatenate([20000 + 150 * rng.random(12), 29800 + 200 * rng.random(4), [0, 100]])
    ys = np.concatenate([350 + 10 * rng.random(12), [980, 990, 1000, 20], [0, 1000]])
    ax.plot(xs, ys, "o", mfc="none", mec="black")
    ax.set_xlim(0, 30000)
    ax.set_ylim(0, 1000)
    fig.tight_layout()
    layout = LabelLayout(ax)
    texts = layout.place([dict(x=x, y=y, text=f"{x:,.0f} r/min") for x, y in zip(xs, ys)])
    fig.savefig(png, dpi=150)
    ok = labels_ok(fig, texts)
    plt.close(fig)
    return ok


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Label layout helper of the plot scripts; "
                                     "--self-test draws a crowded case and checks it.")
    parser.add_argument("--self-test", metavar="OUT.png", help="write the crowded test picture here")
    args = parser.parse_args()
    if args.self_test:
        sys.exit(0 if _self_test(args.self_test) else 1)
    parser.print_help()
