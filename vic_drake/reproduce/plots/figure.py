"""The Figure every plot function returns: one that Jupyter displays.

The plot functions build figures without pyplot (no global state, nothing
left open in a long run). Such a bare ``matplotlib.figure.Figure`` shows in
a notebook only as the text ``<Figure size ... with N Axes>``; a
:class:`NotebookFigure` also has ``_repr_png_``, so Jupyter shows it as an
image whatever the backend, and it is still an ordinary Figure
(``savefig``, ``axes``, ...).
"""

from __future__ import annotations

import io

from matplotlib.figure import Figure

#: Resolution of the image a notebook shows, dots per inch.
NOTEBOOK_DPI = 80


class NotebookFigure(Figure):
    """A matplotlib Figure that Jupyter (IPython's display) shows as a PNG."""

    def _repr_png_(self) -> bytes:
        buf = io.BytesIO()
        self.savefig(buf, format="png", dpi=NOTEBOOK_DPI, bbox_inches="tight")
        return buf.getvalue()


def new_figure(**kwargs) -> NotebookFigure:
    """A new :class:`NotebookFigure` (keyword arguments as ``Figure``'s)."""
    return NotebookFigure(**kwargs)


__all__ = ["NOTEBOOK_DPI", "NotebookFigure", "new_figure"]
