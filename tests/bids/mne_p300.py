"""Reads an ARBCI run from a BIDS dataset with MNE, as an analyst would, and prints the P300.

Usage: mne_p300.py EEG_BDF EVENTS_TSV
Epochs the EEG on the flashes of the events table (target T against N), -100 to 800 ms with the
100 ms before the flash as the baseline, and prints, for Cz and Pz, the mean amplitude of the
attended flashes' average in 250-500 ms and the same for the others, in microvolts, one line
each: "Pz 12.3 -0.4 (T, N; 96 and 283 epochs)". Exits 1 when MNE cannot read the files.
"""
import csv
import sys

import mne
import numpy as np


def main():
    bdf, events_tsv = sys.argv[1], sys.argv[2]
    raw = mne.io.read_raw_bdf(bdf, preload=True, verbose="error")
    rows = list(csv.DictReader(open(events_tsv, newline=""), delimiter="\t"))
    flashes = [r for r in rows if r["trial_type"] == "flash" and r["target"] in ("T", "N")]
    if not flashes:
        print("no flashes with T or N in", events_tsv)
        return 1
    # The sample column is the recording's sample; the onset column the same in seconds.
    events = np.array(
        [[int(r["sample"]), 0, 1 if r["target"] == "T" else 2] for r in flashes], dtype=int
    )
    for r, e in zip(flashes, events):
        if abs(float(r["onset"]) * raw.info["sfreq"] - e[0]) > 0.5:
            print("onset and sample disagree:", r)
            return 1
    picks = [c for c in ("Cz", "Pz") if c in raw.ch_names]
    epochs = mne.Epochs(raw, events, {"T": 1, "N": 2}, tmin=-0.1, tmax=0.8, baseline=(None, 0),
                        picks=picks, preload=True, verbose="error")
    window = (epochs.times >= 0.25) & (epochs.times <= 0.5)
    target = epochs["T"].average().get_data(units="uV")
    other = epochs["N"].average().get_data(units="uV")
    for i, name in enumerate(picks):
        print(f"{name} {target[i, window].mean():.2f} {other[i, window].mean():.2f} "
              f"(T, N; {len(epochs['T'])} and {len(epochs['N'])} epochs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
