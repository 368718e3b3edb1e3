"""The probabilities of the joint fragility fits' models and their derivatives
(``rocksweep.analysis.likelihood`` maximises their likelihoods), in standardised ln IM z:

- the ordinal probit with a common beta (``ordinal_probs``, ``ordinal_jac``);
- the ordinal probit with a beta per state, the parallel test's free model
  (``free_ordinal_probs``, ``free_ordinal_jac``);
- competing lognormal capacities of mode 1 and mode 2 (``cif``, ``cif_jac``; ``phi2``,
  the bivariate normal CDF by Owen's T).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtr, owens_t


def ordinal_probs(z: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """log P(category c | z) (b, K+1, P) of the ordinal probit: theta (b, K+1) = (t_1,
    log(t_2 - t_1), ..., log(t_K - t_{K-1}), log s); P(DS >= j) = Phi(s (z - t_j)). Each
    difference of Phi is taken in the tail where it does not cancel."""
    K = theta.shape[1] - 1
    t = np.cumsum(np.concatenate([theta[:, :1], np.exp(theta[:, 1:K])], 1), 1)  # (b, K)
    s = np.exp(theta[:, K])
    e = s[:, None, None] * (z[:, None, :] - t[:, :, None])  # (b, K, P)
    lower_q, upper_q = ndtr(e), ndtr(-e)  # P(DS >= j), P(DS < j)
    one = np.ones(e.shape[:1] + (1,) + e.shape[2:])
    zero = np.zeros_like(one)
    up_q = np.concatenate([one, lower_q], 1)  # P(DS >= c)
    lo_q = np.concatenate([lower_q, zero], 1)  # P(DS >= c + 1)
    up_c = np.concatenate([zero, upper_q], 1)  # P(DS < c)
    lo_c = np.concatenate([upper_q, one], 1)  # P(DS < c + 1)
    e_next = np.concatenate([e, np.full_like(one, -np.inf)], 1)
    p = np.where(e_next > 0.0, lo_c - up_c, up_q - lo_q)
    with np.errstate(divide="ignore"):
        return np.log(np.maximum(p, 0.0))


def ordinal_jac(z: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """d P(category c | z) / d theta (b, K+1, K+1, P) (parameter, category, level) of
    ``ordinal_probs``' model, analytic: with e_j = s (z - t_j), q_j = Phi(e_j) = P(DS >=
    j), dq_j = phi(e_j) (e_j dlog s - s dt_j), t_j = theta_0 + sum_{1 <= i < j}
    exp(theta_i) (states j = 0..K-1), and P(c) = q_{c-1} - q_c (q_{-1} = 1, q_K = 0)."""
    b, K1 = theta.shape
    K = K1 - 1
    t = np.cumsum(np.concatenate([theta[:, :1], np.exp(theta[:, 1:K])], 1), 1)  # (b, K)
    s = np.exp(theta[:, K])
    e = s[:, None, None] * (z[:, None, :] - t[:, :, None])  # (b, K, P)
    phi = np.exp(-0.5 * e * e) * (1.0 / math.sqrt(2.0 * math.pi))
    # dt_j / dtheta_i (b, K, K): 1 for i = 0, exp(theta_i) for 1 <= i <= j
    dt = np.tril(np.broadcast_to(np.concatenate([np.ones((b, 1)), np.exp(theta[:, 1:K])],
                                                1)[:, None, :], (b, K, K)))
    dq = np.empty((b, K1, K + 2) + z.shape[-1:])  # (b, parameter, q_{-1}..q_K, P)
    dq[:, :, 0] = 0.0
    dq[:, :, -1] = 0.0
    dq[:, :K, 1:-1] = -(s[:, None, None, None] * dt.transpose(0, 2, 1)[..., None]) * \
        phi[:, None]
    dq[:, K, 1:-1] = e * phi
    return dq[:, :, :-1] - dq[:, :, 1:]


def free_ordinal_probs(z: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """P(category c | z) (b, K+1, P) of the ordinal probit with a beta per state: theta
    (b, 2K) = (t_1..t_K, log s_1..log s_K), P(DS >= j) = q_j = Phi(s_j (z - t_j)), P(c) =
    q_{c-1} - q_c (q_0 = 1, q_{K+1} = 0), 0 where the curves cross."""
    K = theta.shape[1] // 2
    t, s = theta[:, :K], np.exp(theta[:, K:])
    cum = ndtr(s[:, :, None] * (z[None, None, :] - t[:, :, None]))  # P(DS >= j)
    one = np.ones((theta.shape[0], 1, z.size))
    return np.maximum(np.concatenate([one, cum], 1) - np.concatenate([cum, 0.0 * one], 1),
                      0.0)


def free_ordinal_jac(z: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """d P(category c | z) / d theta (b, 2K, K+1, P) of ``free_ordinal_probs``, analytic:
    dq_j/dt_j = -s_j phi(e_j), dq_j/dlog s_j = e_j phi(e_j), e_j = s_j (z - t_j); 0 where
    the probability is clipped to 0."""
    K = theta.shape[1] // 2
    t, s = theta[:, :K], np.exp(theta[:, K:])
    e = s[:, :, None] * (z[None, None, :] - t[:, :, None])  # (b, K, P)
    phi = np.exp(-0.5 * e * e) / math.sqrt(2.0 * math.pi)
    dq = np.zeros((theta.shape[0], 2 * K, K + 2, z.size))  # q_0..q_{K+1}
    j = np.arange(K)
    dq[:, j, j + 1] = -s[:, :, None] * phi
    dq[:, K + j, j + 1] = e * phi
    cum = ndtr(e)
    one = np.ones((theta.shape[0], 1, z.size))
    raw = np.concatenate([one, cum], 1) - np.concatenate([cum, 0.0 * one], 1)
    return np.where(raw[:, None] > 0.0, dq[:, :, :-1] - dq[:, :, 1:], 0.0)


def cif(z: np.ndarray, t: np.ndarray, sig: np.ndarray) -> tuple[np.ndarray, ...]:
    """Competing lognormal capacities in standardised ln IM: z (..., P), t and sig (..., 2)
    the two capacities' means and deviations. Returns (P(safe), P(mode 1), P(mode 2))
    (..., P): P(mode k) = P(U_k <= z, U_k < U_other) = Phi2(h, q; rho), h = (z - t_k) /
    sig_k, q = (t_o - t_k) / sqrt(sig_k^2 + sig_o^2), rho = sig_k / sqrt(...) (Owen's T)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = []
        tot = np.sqrt(sig[..., 0] ** 2 + sig[..., 1] ** 2)
        for k, o in ((0, 1), (1, 0)):
            h = (z - t[..., k, None]) / sig[..., k, None]
            q = np.broadcast_to(((t[..., o] - t[..., k]) / tot)[..., None], h.shape)
            rho = np.broadcast_to((sig[..., k] / tot)[..., None], h.shape)
            out.append(phi2(h, q, rho))
        safe = ndtr(-(z - t[..., 0, None]) / sig[..., 0, None]) * ndtr(
            -(z - t[..., 1, None]) / sig[..., 1, None])
    return safe, out[0], out[1]


def phi2(h: np.ndarray, k: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """Bivariate standard normal CDF P(X <= h, Y <= k), corr rho in (0, 1), by Owen's T:
    Phi2 = Phi(h)/2 + Phi(k)/2 - T(h, a_h) - T(k, a_k) - [hk < 0]/2 (Owen 1956)."""
    r = np.sqrt(1.0 - rho * rho)
    h = np.where(h == 0.0, 1e-300, h)
    k = np.where(k == 0.0, 1e-300, k)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        ah = (k - rho * h) / (h * r)
        ak = (h - rho * k) / (k * r)
    p = 0.5 * ndtr(h) + 0.5 * ndtr(k) - owens_t(h, ah) - owens_t(k, ak) - np.where(
        h * k < 0.0, 0.5, 0.0)
    return np.clip(p, 0.0, 1.0)


def cif_jac(z: np.ndarray, t: np.ndarray, sig: np.ndarray) -> np.ndarray:
    """d (P(safe), P(mode 1), P(mode 2)) / d (t_1, log sig_1, t_2, log sig_2) (b, 4, 3, P)
    of ``cif``, analytic: P(mode k | z) = integral to z of f_k S_o (f_k the density of
    U_k, S_o the survival of the other), so with the Gaussian product f_k f_o = C N(m, v)
    (C the N(0, sig_k^2 + sig_o^2) density at t_k - t_o), I0 = integral to z of f_k f_o
    = C Phi(w), I1 = integral to z of u f_k f_o = C (m Phi(w) - sqrt(v) phi(w)), w = (z -
    m) / sqrt(v): dP_k/dt_o = I0, dP_k/dlog sig_o = I1 - t_o I0, dP_k/dt_k = -f_k(z)
    S_o(z) - I0, dP_k/dlog sig_k = -(z - t_k) f_k(z) S_o(z) - (I1 - t_k I0) (by parts);
    P(safe) = 1 - P(mode 1) - P(mode 2)."""
    t1, t2 = t[:, :1], t[:, 1:]
    v1, v2 = sig[:, :1] ** 2, sig[:, 1:] ** 2
    tot = v1 + v2
    c = np.exp(-0.5 * (t1 - t2) ** 2 / tot) / np.sqrt(2.0 * math.pi * tot)  # (b, 1)
    m = (t1 * v2 + t2 * v1) / tot
    sv = np.sqrt(v1 * v2 / tot)
    w = (z - m) / sv  # (b, P)
    cdf_w = ndtr(w)
    pdf_w = np.exp(-0.5 * w * w) / math.sqrt(2.0 * math.pi)
    i0 = c * cdf_w
    i1 = c * (m * cdf_w - sv * pdf_w)
    J = np.empty((z.shape[0], 4, 3, z.shape[1]))
    for k in (0, 1):
        o = 1 - k
        tk, to = t[:, k:k + 1], t[:, o:o + 1]
        hk = (z - tk) / sig[:, k:k + 1]
        fk_so = np.exp(-0.5 * hk * hk) / (math.sqrt(2.0 * math.pi) * sig[:, k:k + 1]) * \
            ndtr(-(z - to) / sig[:, o:o + 1])
        J[:, 2 * k, k + 1] = -fk_so - i0
        J[:, 2 * k + 1, k + 1] = -(z - tk) * fk_so - (i1 - tk * i0)
        J[:, 2 * o, k + 1] = i0
        J[:, 2 * o + 1, k + 1] = i1 - to * i0
    J[:, :, 0] = -(J[:, :, 1] + J[:, :, 2])
    return J
