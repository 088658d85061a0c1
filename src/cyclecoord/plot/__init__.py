"""Figures of every stage (barcode, PCA, density, coordinate, channels, windows) and renders."""

from .figures import (
    plot_barcode,
    plot_pca,
    plot_density,
    plot_coordinate,
    plot_windows,
    plot_channels,
    save_figures,
    render,
)

__all__ = [
    "plot_barcode",
    "plot_pca",
    "plot_density",
    "plot_coordinate",
    "plot_windows",
    "plot_channels",
    "save_figures",
    "render",
]
