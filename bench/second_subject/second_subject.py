#!/usr/bin/python3
"""A second simulated subject, made differently from arbci's own (bci/src/simulated_subject.cpp),
so that figures measured on that one can be checked on data it did not shape: written from
textbook P300-speller physiology, not from arbci's generator. Background: 200 cortical sources,
each with a smooth lead field and a 1/f^beta spectrum shaped in the frequency domain, bursting
posterior alpha, scaled to 8-12 uV RMS in 1-20 Hz; sensor noise, mains, electrode drift, frontal
blinks (one per 4 s on average), muscle bursts. Responses: a visual P1/N1 to every flash; to a
target a P3b (parietal, 3.5-8 uV, raised-cosine, 330-480 ms) with a P3a (fronto-central) and a
lateral visual N2 (PO7/PO8), skewed latency jitter, habituation over the session (-30 %),
attention lapses (10 % of target flashes without a response) and a smaller response to a target
within 0.5 s of the last. It replaces the EEG samples of a copy-task recording that `arbci eeg
simulate` wrote, keeping its stimuli, labels and every other channel.

Usage: second_subject.py IN.bdf OUT.bdf SEED [--p3-scale 0.5] [--no-blinks]
Needs python3-numpy and python3-scipy (Debian)."""
import argparse
import math
import shutil

import numpy as np
from scipy.signal import butter, sosfiltfilt

import bdf_io as bdfio

POS = {  # polar (theta deg from nose, clockwise; radius 0.5 = 90 deg from vertex)
    'FZ': (0, 0.256), 'CZ': (0, 0.0), 'P3': (-141, 0.333), 'PZ': (180, 0.256), 'P4': (141, 0.333),
    'PO7': (-144, 0.511), 'OZ': (180, 0.511), 'PO8': (144, 0.511), 'FP1': (-18, 0.511),
    'FP2': (18, 0.511), 'C3': (-90, 0.256), 'C4': (90, 0.256), 'O1': (-162, 0.511),
    'O2': (162, 0.511), 'FCZ': (0, 0.128), 'CPZ': (180, 0.128), 'POZ': (180, 0.383)}

def xy(name):
    th, r = POS[name.upper()]
    t = math.radians(th)
    return np.array([r * math.sin(t), r * math.cos(t)])

def spectral_noise(rng, n, rate, beta, peak=None):
    """Gaussian noise with power ~ 1/f^beta (and an optional resonance), unit variance."""
    f = np.fft.rfftfreq(n, 1.0 / rate)
    amp = 1.0 / np.maximum(f, 0.2) ** (beta / 2.0)
    if peak is not None:
        fc, bw = peak
        amp = np.exp(-0.5 * ((f - fc) / bw) ** 2)
    spec = amp * (rng.standard_normal(len(f)) + 1j * rng.standard_normal(len(f)))
    x = np.fft.irfft(spec, n)
    return x / x.std()

def topo(names, centre, width):
    c = np.asarray(centre)
    return np.array([math.exp(-np.sum((xy(nm) - c) ** 2) / (2 * width ** 2)) for nm in names])

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source", help="a recording of `arbci eeg simulate` (copy task, BDF+)")
    parser.add_argument("out", help="the recording to write")
    parser.add_argument("seed", type=int, help="draws the subject and its noise")
    parser.add_argument("--p3-scale", type=float, default=1.0,
                        help="scales the target responses (0.5: half the P300)")
    parser.add_argument("--no-blinks", action="store_true", help="leave the blinks out")
    args = parser.parse_args()
    src, dst, seed, scale = args.source, args.out, args.seed, args.p3_scale
    shutil.copyfile(src, dst)
    h, chans, ann = bdfio.read(dst)
    eeg = [i for i, l in enumerate(h['labels']) if l.upper() in POS]
    names = [h['labels'][i] for i in eeg]
    rate = h['nsamp'][eeg[0]] / h['dur']
    n = len(chans[eeg[0]])
    rng = np.random.default_rng(1_000_003 * seed + 7)
    C = len(eeg)
    X = np.zeros((C, n))

    # Background: many cortical sources on the head (volume conduction: a smooth lead field each),
    # 1/f^beta spectra, bursting posterior alpha; scaled to a resting-EEG level in 1-20 Hz.
    for _ in range(200):
        pos = rng.uniform(-0.55, 0.55, 2)
        lead = topo(names, pos, rng.uniform(0.15, 0.4))
        X += np.outer(lead, rng.uniform(0.5, 1.5) * spectral_noise(rng, n, rate, rng.uniform(1.0, 2.0)))
    for centre in ([-0.2, -0.45], [0.2, -0.45]):
        lead = topo(names, centre, 0.3)
        carrier = spectral_noise(rng, n, rate, 0, peak=(rng.uniform(9, 11.5), 0.6))
        envelope = np.abs(spectral_noise(rng, n, rate, 0, peak=(0.0, 0.3)))
        X += np.outer(lead, rng.uniform(1.0, 2.5) * carrier * envelope)
    band = sosfiltfilt(butter(4, [1, 20], 'bandpass', fs=rate, output='sos'), X, axis=1)
    X *= rng.uniform(8.0, 12.0) / np.sqrt(np.mean(band ** 2))
    # Sensor noise, line, drift.
    t = np.arange(n) / rate
    for c in range(C):
        X[c] += rng.uniform(1.0, 2.0) * rng.standard_normal(n)
        X[c] += rng.uniform(0.5, 3.0) * np.sin(2 * np.pi * 50 * t + rng.uniform(0, 2 * np.pi))
        X[c] += rng.uniform(5, 20) * spectral_noise(rng, n, rate, 0, peak=(0.0, 0.08))
    # Blinks (frontal), muscle bursts (lateral posterior).
    blink_lead = topo(names, [0.0, 0.6], 0.25)
    k = 0
    while True:
        k += int(rng.exponential(4.0) * rate)
        if k >= n: break
        L = int(rng.uniform(0.25, 0.4) * rate)
        w = np.sin(np.linspace(0, np.pi, L)) ** 2 * rng.uniform(60, 140)
        seg = slice(k, min(n, k + L))
        if not args.no_blinks:
            X[:, seg] += np.outer(blink_lead, w[:seg.stop - seg.start])
    k = 0
    while True:
        k += int(rng.exponential(30.0) * rate)
        if k >= n: break
        L = int(rng.uniform(0.3, 1.0) * rate)
        side = [-0.4, -0.4] if rng.uniform() < 0.5 else [0.4, -0.4]
        lead = topo(names, side, 0.2)
        burst = rng.standard_normal(L) * np.hanning(L) * rng.uniform(5, 15)
        seg = slice(k, min(n, k + L))
        X[:, seg] += np.outer(lead, burst[:seg.stop - seg.start])

    # Evoked responses.
    stim = bdfio.stimuli(ann)
    p3b_amp = rng.uniform(3.5, 8.0) * scale
    p3b_lat = rng.uniform(0.33, 0.48)
    p3b_len = rng.uniform(0.25, 0.40)
    p3a_amp = rng.uniform(1.0, 3.0) * scale
    p3a_lat = rng.uniform(0.25, 0.31)
    n2_amp = rng.uniform(2.0, 5.0) * scale
    p3b_lead = topo(names, xy('Pz') + rng.normal(0, 0.07, 2), rng.uniform(0.25, 0.4))
    p3a_lead = topo(names, xy('Fz') * 0.6, 0.3)
    # The visual N2 of spellers: lateral occipito-parietal, both sides (PO7, PO8).
    n2_lead = topo(names, xy('PO7'), 0.2) + topo(names, xy('PO8'), 0.2)
    vep_lead = topo(names, xy('Oz'), 0.3)
    vep_amp = rng.uniform(2, 5)
    T = t[-1]
    last_target = -10.0
    def hann(centre, length, at):
        u = (at - centre) / length
        return np.where(np.abs(u) < 0.5, np.cos(np.pi * u) ** 2, 0.0)
    for onset, code, flag in stim:
        s0 = int(round(onset * rate))
        L = int(1.0 * rate)
        if s0 + L > n: continue
        tt = np.arange(L) / rate
        # Every flash: P1/N1 as a damped sine.
        vep = vep_amp * np.exp(-tt / 0.08) * np.sin(2 * np.pi * 6 * (tt - 0.06)) * (tt > 0.06)
        X[:, s0:s0 + L] += np.outer(vep_lead, vep)
        if flag != 'T': continue
        a = 1.0 - 0.3 * onset / T  # habituation
        if onset - last_target < 0.5: a *= 0.6  # refractory
        last_target = onset
        if rng.uniform() < 0.1: continue  # lapse
        jit = rng.gamma(4.0, 0.012) - 0.048  # skewed, mean 0
        a *= math.exp(rng.normal(0, 0.3))
        w = (p3b_amp * a * hann(p3b_lat + jit, p3b_len, tt))
        X[:, s0:s0 + L] += np.outer(p3b_lead, w)
        X[:, s0:s0 + L] += np.outer(p3a_lead, p3a_amp * a * hann(p3a_lat + 0.5 * jit, 0.15, tt))
        X[:, s0:s0 + L] -= np.outer(n2_lead, n2_amp * a * hann(0.24 + 0.3 * jit, 0.12, tt))

    new = [None] * h['ns']
    for j, i in enumerate(eeg):
        new[i] = X[j]
    bdfio.write_channels(dst, h, new)
    sd = X.std(axis=1)
    print(f"{dst}: P3b {p3b_amp:.1f} uV at {p3b_lat*1000:.0f} ms, channel SD {sd.min():.1f}-{sd.max():.1f} uV")


if __name__ == "__main__":
    main()
