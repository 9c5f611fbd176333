"""Reads and rewrites the samples of a BDF(+) file in place (24-bit, per-channel scaling) and
lists its "Stim <code> T|N|U" annotations: what second_subject.py needs, nothing more."""
import numpy as np, re

def read_header(path):
    with open(path, 'rb') as f:
        h = f.read(256)
        ns = int(h[252:256].decode().strip())
        nrec = int(h[236:244].decode().strip())
        dur = float(h[244:252].decode().strip())
        hb = int(h[184:192].decode().strip())
        f.seek(256)
        s = f.read(ns * 256)
    def field(off, width):
        return [s[off + i * width: off + (i + 1) * width].decode('latin-1').strip() for i in range(ns)]
    o = 0
    labels = field(o, 16); o += 16 * ns
    o += 80 * ns  # transducer
    dims = field(o, 8); o += 8 * ns
    pmin = [float(x) for x in field(o, 8)]; o += 8 * ns
    pmax = [float(x) for x in field(o, 8)]; o += 8 * ns
    dmin = [float(x) for x in field(o, 8)]; o += 8 * ns
    dmax = [float(x) for x in field(o, 8)]; o += 8 * ns
    o += 80 * ns  # prefilter
    nsamp = [int(x) for x in field(o, 8)]
    return dict(ns=ns, nrec=nrec, dur=dur, hb=hb, labels=labels, dims=dims, pmin=pmin, pmax=pmax,
                dmin=dmin, dmax=dmax, nsamp=nsamp)

def read(path):
    h = read_header(path)
    raw = np.fromfile(path, dtype=np.uint8, offset=h['hb'])
    rec_bytes = 3 * sum(h['nsamp'])
    nrec = len(raw) // rec_bytes
    raw = raw[:nrec * rec_bytes].reshape(nrec, rec_bytes)
    chans, off = [], 0
    ann = b''
    for i in range(h['ns']):
        n = h['nsamp'][i]
        block = raw[:, off:off + 3 * n]
        off += 3 * n
        if h['labels'][i] == 'BDF Annotations':
            ann = block.tobytes()
            chans.append(None)
            continue
        b = block.reshape(nrec, n, 3).astype(np.int32)
        v = b[..., 0] | (b[..., 1] << 8) | (b[..., 2] << 16)
        v = np.where(v >= 1 << 23, v - (1 << 24), v).reshape(-1)
        gain = (h['pmax'][i] - h['pmin'][i]) / (h['dmax'][i] - h['dmin'][i])
        chans.append((v - h['dmin'][i]) * gain + h['pmin'][i])
    h['nrec_read'] = nrec
    return h, chans, ann

def stimuli(ann):
    """(onset_s, code, flag) of every 'Stim c T|N|U' annotation."""
    out = []
    for tal in ann.split(b'\x00'):
        if not tal:
            continue
        parts = tal.split(b'\x14')
        head = parts[0].split(b'\x15')
        try:
            onset = float(head[0].decode())
        except ValueError:
            continue
        for text in parts[1:]:
            m = re.match(rb'Stim (\d+) ([TNU])', text)
            if m:
                out.append((onset, int(m.group(1)), m.group(2).decode()))
    return out

def write_channels(path, h, new):
    """Overwrites the samples of channel i with new[i] (physical units) where new[i] is not None."""
    raw = np.fromfile(path, dtype=np.uint8, offset=h['hb'])
    rec_bytes = 3 * sum(h['nsamp'])
    nrec = h['nrec_read']
    body = raw[:nrec * rec_bytes].reshape(nrec, rec_bytes).copy()
    off = 0
    for i in range(h['ns']):
        n = h['nsamp'][i]
        if new[i] is not None:
            gain = (h['pmax'][i] - h['pmin'][i]) / (h['dmax'][i] - h['dmin'][i])
            d = np.round((np.asarray(new[i][:nrec * n]) - h['pmin'][i]) / gain + h['dmin'][i])
            d = np.clip(d, h['dmin'][i], h['dmax'][i]).astype(np.int64)
            d = np.where(d < 0, d + (1 << 24), d).reshape(nrec, n)
            b = np.stack([d & 0xFF, (d >> 8) & 0xFF, (d >> 16) & 0xFF], axis=-1).astype(np.uint8)
            body[:, off:off + 3 * n] = b.reshape(nrec, 3 * n)
        off += 3 * n
    with open(path, 'r+b') as f:
        f.seek(h['hb'])
        f.write(body.tobytes())
