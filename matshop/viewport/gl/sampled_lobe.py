"""A sampled (tabulated) lobe as one 2D array texture: its table and its sampling nodes.

The reference renderer reads a sampled lobe twice (:mod:`matshop.render.integrator`):
``D(h)`` for the directional lights from the table ``d`` itself (``N`` bins uniform
in ``theta``, :func:`matshop.render.brdf.sampled_d`), and the environment samples
from its inverse CDF, the sampled space's quantiles ``theta`` at ``M`` fixed levels
``y`` (:func:`matshop.render.sampling.sample_quantiles`: ``theta(u1)`` linear
between the two levels around ``u1``, the pdf from that segment's slope). The GPU
gets exactly those numbers, so it reads what the reference reads:

- layers ``[0, ceil(N / 4))``: the table, 4 bins a layer, zeros after the last bin;
- the next :data:`NODE_LAYERS` layers: ``theta`` at the :data:`NODES` levels of the
  space around the ``u1 = (j + 1/2) / 16`` of a 16-point Hammersley set (the two
  levels bracketing each), whose ``y`` the shader gets as a uniform
  (:func:`node_levels`). With the viewport's 16 samples each sample's segment is
  the reference's own, so directions and pdfs are the reference's; other sample
  counts read the inverse CDF linearly between these 32 nodes.

Both are linear in what they store, so bilinear filtering between texels is the
reference's bilinear interpolation of tables and of quantiles (Read's
interpolation of distributions). Mip levels are not: the reference's prefilter
averages the *tables* (the mixture of the texels' lobes) and samples the mixture,
so each coarser level's nodes are its averaged table's (:func:`renode`).

(The GPU used to read ``D`` from 17 segments of a 16-level inverse CDF, in
``x = sin^2 theta``: a lobe narrower than a few of the table's 0.7-degree bins --
GGX alpha below ~0.03, the bundled sample's metal -- read ``D(0)`` about 1370 there
against the table's 578, the inverse CDF having been interpolated across
under-resolved bins; ``tests/test_viewport_gl_lobes.py`` measured it.)

Half floats: ``d`` of a bin is at most ``1 / (its measure)`` (about 2100 for bin 0
of 128), well inside their range; angles keep 11 bits.
"""

from __future__ import annotations

import numpy as np

from ...ops.sampled_widening import widen_tabulated
from ...render.surface import lobe_quantiles, sampled_space

#: the viewport's environment samples per pixel, whose u1 the nodes bracket
SAMPLES = 16
#: stored inverse-CDF nodes (two per sample) and the texture layers they take
NODES = 2 * SAMPLES
NODE_LAYERS = NODES // 4


def table_layers(n_bins: int) -> int:
    """Layers of 4 that hold ``n_bins`` bins."""
    return -(-n_bins // 4)


def layers(n_bins: int) -> int:
    """Layers of the whole texture for a table of ``n_bins`` bins."""
    return table_layers(n_bins) + NODE_LAYERS


def node_indices(levels: np.ndarray) -> np.ndarray:
    """Which of the space's ``levels`` (``M``, increasing) are stored: the two around each
    sample's ``u1``, found as the reference's sampler finds them (``y = 0`` and ``1``,
    the implied ends, are not stored); repeated at the end up to :data:`NODES`."""
    y = np.concatenate([[0.0], np.asarray(levels, dtype=np.float64), [1.0]])
    u1 = (np.arange(SAMPLES) + 0.5) / SAMPLES
    k = np.clip(np.searchsorted(y, u1, side="right") - 1, 0, y.size - 2)
    padded = np.union1d(k, k + 1)
    inner = padded[(padded >= 1) & (padded <= y.size - 2)] - 1
    return np.concatenate([inner, np.full(NODES - inner.size, inner[-1])]).astype(np.intp)


def node_levels(n_bins: int) -> np.ndarray:
    """The ``y`` of the stored nodes (:data:`NODES`,) float32 of tables of ``n_bins`` bins:
    the shader's ``u_node_y``."""
    levels = sampled_space(n_bins).y
    return levels[node_indices(levels)].astype(np.float32)


def _nodes(table: np.ndarray) -> np.ndarray:
    """``theta`` ``(H, W, NODES)`` at the stored levels of tables ``(H, W, N)``."""
    quantiles, levels = lobe_quantiles(np.ascontiguousarray(table, dtype=np.float32))
    return quantiles[..., node_indices(levels)]


def pack(table: np.ndarray, quantiles: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """Tables ``(H, W, N)`` and their inverse CDF ``(H, W, M)`` at ``levels`` (what
    :func:`matshop.render.surface.prepare` computed) -> the texture's ``(H, W, 4 layers(N))``
    float32 texels."""
    n = table.shape[-1]
    padded = np.pad(table, ((0, 0), (0, 0), (0, 4 * table_layers(n) - n)))
    nodes = quantiles[..., node_indices(levels)]
    return np.concatenate([padded, nodes], axis=2).astype(np.float32)


def renode(texels: np.ndarray, n_bins: int) -> np.ndarray:
    """``texels`` of a coarser mip level (averaged tables) with the nodes of those tables
    (their averaged nodes would be Read's interpolation, not the mixture)."""
    split = 4 * table_layers(n_bins)
    nodes = _nodes(texels[..., :n_bins])
    return np.concatenate([texels[..., :split], nodes], axis=2)


def widen(texels: np.ndarray, n_bins: int, added: np.ndarray) -> np.ndarray:
    """``texels`` whose tables are widened by the total slope variance ``added`` ``(H, W)``
    (keep variance: :func:`matshop.ops.sampled_widening.widen_tabulated`); the nodes are
    left for :func:`renode`."""
    out = texels.copy()
    out[..., :n_bins] = widen_tabulated(texels[..., :n_bins], added)
    return out
