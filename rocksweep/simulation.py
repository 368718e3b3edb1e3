"""What ``rocksweep.simulate`` returns: one run of one point, its summary, its time
history and its Figure 5. A result type of the API (``rocksweep.api``), on its floor: it
draws through ``rocksweep.figures``, which ``rocksweep.compute`` (where its run comes from,
``compute.history``) may not import."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from rocksweep.compute.single import Run


@dataclass
class Simulation:
    """One run of one point (``rocksweep.simulate``).

    summary: plain dict (``rocksweep simulate --json``: outcome, impacts, uplifts,
    theta_max_over_alpha, t_overturn, t_first_impact, energies / E_ref, status words,
    steps, event_steps, accuracy, wall_time_s); history: xarray Dataset over ``p_t``
    (``rocksweep.fields.HISTORY``: theta_over_alpha, u_over_ucr, E_over_Eref, ..., each
    with ``units``; at an event p_t repeats: the rows before and after it); run: the
    underlying ``rocksweep.compute.single.Run``.
    """

    summary: dict
    history: xr.Dataset
    run: Run
    title: str = ""

    def figure(self) -> Figure:
        """Figure 5 for this run (pulse, theta/alpha, E/E_ref, dissipated energy against
        p*t) as a pyplot-free matplotlib Figure: show it in a notebook or ``savefig``."""
        # matplotlib (~1 s): when the figure is asked for
        from rocksweep.figures.history import time_history

        return time_history([self.run], (), self.title)
