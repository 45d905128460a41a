"""Reproducible conversion: TCIA CPTAC-PDA chest CT (via xcist/phantoms-voxelized) -> volume_hu.npy, mu.npy, PNGs.
Run with /usr/bin/python3 (numpy, scipy, PIL). Inputs: the 102 DICOM files extracted by extract_xcist.sh into src/xcist/body/."""
import sys, json, numpy as np
from scipy import ndimage
from PIL import Image
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__))); from load import load_series
OUT = (sys.argv[1] if len(sys.argv) > 1 else '.') + '/'
NZ, NXY = 100, 256
MU_WATER = 0.02      # 1/mm

hu, zpos, infos, names = load_series(OUT + 'src/xcist/body')          # [z,y,x], z ascending (inferior->superior)
px = float(infos[0]['PixelSpacing'].split('\\')[0]); dz = float(np.median(np.diff(zpos)))
np.save(OUT + 'volume_hu.npy', hu.astype(np.float32))

# body mask: HU > -300, per-slice opening with a 13x13 disk (breaks the thin table-top shell and the
# cushion contact), largest 3-D component, then regrown by 8 geodesic dilations inside HU > -500 and hole-filled per slice
MASK_TABLE = True      # True: voxels outside the body mask are set to air (mu = 0) in mu.npy (removes the patient table)
yy, xx = np.mgrid[-6:7, -6:7]; disk = (yy**2 + xx**2) <= 36
m = ndimage.binary_opening(hu > -300, structure=disk[None])
lab, n = ndimage.label(m); sizes = ndimage.sum(m, lab, range(1, n + 1))
body = lab == (1 + int(np.argmax(sizes)))
body = ndimage.binary_dilation(body, structure=np.ones((1, 3, 3), bool), iterations=8, mask=hu > -500)
body = np.stack([ndimage.binary_fill_holes(b) for b in body])
# z-range: the NZ contiguous slices with the largest body volume
area = body.sum(axis=(1, 2)); csum = np.convolve(area, np.ones(NZ), 'valid'); z0 = int(np.argmax(csum)); z1 = z0 + NZ
# in-plane square crop: body bounding box over the chosen slices, 3% margin, centred
ys, xs = np.where(body[z0:z1].any(axis=0))
cy, cx = (ys.min() + ys.max() + 1) / 2, (xs.min() + xs.max() + 1) / 2
S = int(np.ceil(max(ys.max() - ys.min() + 1, xs.max() - xs.min() + 1) * 1.03))
y0, x0 = int(round(cy - S / 2)), int(round(cx - S / 2))
mu_full = np.clip(MU_WATER * (hu[z0:z1] + 1000.0) / 1000.0, 0, None).astype(np.float32)
if MASK_TABLE: mu_full[~body[z0:z1]] = 0.0
crop = np.zeros((NZ, S, S), np.float32)                               # pad with air (mu=0) if the square leaves the image
sy0, sx0 = max(y0, 0), max(x0, 0); sy1, sx1 = min(y0 + S, hu.shape[1]), min(x0 + S, hu.shape[2])
crop[:, sy0 - y0:sy1 - y0, sx0 - x0:sx1 - x0] = mu_full[:, sy0:sy1, sx0:sx1]
d = S / NXY                                                           # in-plane downsampling factor
if d > 1.5:
    crop = ndimage.gaussian_filter(crop, sigma=(0, (d - 1) / 2, (d - 1) / 2), mode='nearest')
mu = ndimage.zoom(crop, (NZ / crop.shape[0], NXY / S, NXY / S), order=1, grid_mode=True, mode='nearest')
mu = np.clip(mu, 0, None).astype(np.float32)
assert mu.shape == (NZ, NXY, NXY)
np.save(OUT + 'mu.npy', mu)

def png(a, lo, hi, path, sy=1.0):
    im = Image.fromarray((np.clip((a - lo) / (hi - lo), 0, 1) * 255).astype(np.uint8))
    if sy != 1.0: im = im.resize((im.width, int(round(im.height * sy))), Image.BILINEAR)
    im.save(path)
vx = S * px / NXY
lo, hi = 0.0, MU_WATER * 1.4                                          # window: HU -1000 .. +400
png(mu[NZ // 2], lo, hi, OUT + 'mu_axial.png')
png(mu[::-1, NXY // 2, :], lo, hi, OUT + 'mu_coronal.png', sy=dz / vx)   # superior at top, aspect-corrected
png(mu[::-1, :, NXY // 2], lo, hi, OUT + 'mu_sagittal.png', sy=dz / vx)
meta = dict(source_shape=list(hu.shape), pixel_mm=px, slice_mm=dz, z_first=zpos[0], z_last=zpos[-1], z0=z0, z1=z1,
            crop_y0=y0, crop_x0=x0, crop_side_px=S, downsample=d, gauss_sigma_px=((d - 1) / 2 if d > 1.5 else 0),
            mu_voxel_inplane_mm=vx, mu_slice_mm=dz * (z1 - z0) / NZ, hu_range=[float(hu.min()), float(hu.max())],
            mu_range=[float(mu.min()), float(mu.max())], mu_nonfinite=int((~np.isfinite(mu)).sum()), hu_nonfinite=int((~np.isfinite(hu)).sum()),
            mask_table=MASK_TABLE, body_bbox_y=[int(ys.min()), int(ys.max())], body_bbox_x=[int(xs.min()), int(xs.max())], files_first_last=[names[0], names[-1]])
json.dump(meta, open(OUT + 'convert_meta.json', 'w'), indent=1); print(json.dumps(meta, indent=1))
