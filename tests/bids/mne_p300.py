"""Reads an ARBCI run from a BIDS dataset with MNE, as an analyst would, and prints the P300.

Usage: mne_p300.py EEG_BDF EVENTS_TSV
Takes the events table's onsets, durations and trial_type as the recording's annotations (what
mne-bids' read_raw_bids does), makes events of the flashes from them and epochs by trial_type alone
("flash/target" against "flash/nontarget"; no other column), -100 to 800 ms with the 100 ms
before the flash as the baseline, and prints, for Cz and Pz, the mean amplitude of the attended
flashes' average in 250-500 ms and the same for the others, in microvolts, one line each:
"Pz 12.3 -0.4 (T, N; 96 and 283 epochs)". Exits 1 when MNE cannot read the files.
"""
import csv
import sys

import mne
import numpy as np


def main():
    bdf, events_tsv = sys.argv[1], sys.argv[2]
    raw = mne.io.read_raw_bdf(bdf, preload=True, verbose="error")
    rows = list(csv.DictReader(open(events_tsv, newline=""), delimiter="\t"))
    for r in rows:
        if abs(float(r["onset"]) * raw.info["sfreq"] - int(r["sample"])) > 0.5:
            print("onset and sample disagree:", r)
            return 1
    raw.set_annotations(mne.Annotations(
        onset=[float(r["onset"]) for r in rows],
        duration=[float(r["duration"]) for r in rows],
        description=[r["trial_type"] for r in rows]))
    # The flashes only: other events (a phase change, a feedback) may share a flash's sample.
    events, event_id = mne.events_from_annotations(raw, regexp="^flash/", verbose="error")
    if "flash/target" not in event_id or "flash/nontarget" not in event_id:
        print("no flash/target and flash/nontarget in trial_type of", events_tsv, event_id)
        return 1
    picks = [c for c in ("Cz", "Pz") if c in raw.ch_names]
    epochs = mne.Epochs(raw, events, event_id, tmin=-0.1, tmax=0.8, baseline=(None, 0),
                        picks=picks, preload=True, verbose="error")
    window = (epochs.times >= 0.25) & (epochs.times <= 0.5)
    target = epochs["flash/target"].average().get_data(units="uV")
    other = epochs["flash/nontarget"].average().get_data(units="uV")
    for i, name in enumerate(picks):
        print(f"{name} {target[i, window].mean():.2f} {other[i, window].mean():.2f} "
              f"(T, N; {len(epochs['flash/target'])} and {len(epochs['flash/nontarget'])} epochs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
