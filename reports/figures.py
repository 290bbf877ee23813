"""Report figures: one function per figure, each returning a :class:`FigureOut` (PNG bytes,
caption, alt text) or None when the data it needs are missing.

The figures read the tables the harness writes (results, scores, flights, modes, examples,
differentiation, history) and nothing else: this package never flies or estimates. They are
drawn with matplotlib's object-oriented API on the Agg canvas (no pyplot state), so they are
safe to build from several threads or processes.

========================  ==================================================================
function                  figure
========================  ==================================================================
fig_differentiation_error seed Fig. 1: RMS derivative error of the three differentiation methods
fig_bias                  seed Fig. 3: mean bias (% of truth) per parameter and method
fig_model_fit             seed Fig. 4: measured and fitted dependent variable, residual below
fig_residuals             seed Figs. 5-6: residual time history and power spectral density
fig_bias_vs_correlation   seed Fig. 7: bias against the largest regressor correlation
fig_coverage              coverage of the ±2σ intervals with binomial intervals
fig_se_ratio              mean reported SE / empirical SD
fig_efficiency            Cramér-Rao variance / empirical variance
fig_scatter               every realization's estimate of one parameter
fig_time_histories        maneuver inputs and responses
fig_input_spectra         input spectra with the aircraft's mode frequencies
fig_trend                 nightly median coverage and |bias z|
fig_accuracy_vs_cost      median relative RMSE against time per estimate
fig_excursions            peak excursions from trim per maneuver
========================  ==================================================================
"""
from __future__ import annotations

from typing import Callable

import pandas as pd

from reports.figures_common import FigureOut, figure_to_png
from reports.figures_scores import fig_bias, fig_coverage, fig_efficiency, fig_scatter, fig_se_ratio
from reports.figures_flights import fig_excursions, fig_input_spectra, fig_time_histories
from reports.figures_signals import fig_differentiation_error, fig_model_fit, fig_residuals
from reports.figures_trends import fig_accuracy_vs_cost, fig_bias_vs_correlation, fig_trend

__all__ = ["FigureOut", "figure_to_png", "all_figures", "fig_differentiation_error", "fig_bias", "fig_model_fit",
           "fig_residuals", "fig_bias_vs_correlation", "fig_coverage", "fig_se_ratio", "fig_efficiency",
           "fig_scatter", "fig_time_histories", "fig_input_spectra", "fig_trend", "fig_accuracy_vs_cost",
           "fig_excursions"]


def all_figures(results: pd.DataFrame | None = None, scores: pd.DataFrame | None = None,
                flights: pd.DataFrame | None = None, modes: pd.DataFrame | None = None,
                examples: pd.DataFrame | None = None, differentiation: pd.DataFrame | None = None,
                history: pd.DataFrame | None = None) -> list[FigureOut]:
    """Every figure the given tables allow, in report order.

    Parameters
    ----------
    results, scores, flights, modes, examples, differentiation, history : DataFrame, optional
        The harness's tables; a missing one only drops the figures that need it.

    Returns
    -------
    list of FigureOut
        The figures that could be drawn (those returning None are left out).
    """
    makers: list[Callable[[], FigureOut | None]] = [
        lambda: fig_time_histories(flights),
        lambda: fig_input_spectra(flights, modes),
        lambda: fig_excursions(results),
        lambda: fig_differentiation_error(differentiation),
        lambda: fig_bias(scores),
        lambda: fig_scatter(results, scores),
        lambda: fig_coverage(scores),
        lambda: fig_se_ratio(scores),
        lambda: fig_efficiency(scores),
        lambda: fig_bias_vs_correlation(scores),
        lambda: fig_accuracy_vs_cost(scores),
        lambda: fig_model_fit(examples),
        lambda: fig_residuals(examples),
        lambda: fig_trend(history),
    ]
    return [f for f in (make() for make in makers) if f is not None]
