"""A .datx read with h5py (Debian's python3-h5py) the way prysm 0.21.1's read_zygo_datx reads it
(prysm/io.py): the first dataset under Data/Surface, its attributes 'No Data', 'Wavelength',
'Unit', 'Interferometric Scale Factor' and 'Obliquity Factor' as 1-element arrays, pixels >= No
Data as NaN, and the lateral resolution from the last group under Attributes. Prints JSON.

usage: read_datx_h5py.py FILE.datx [SURFACE_NM.npy]
With an .npy (numpy's own reader), says whether the heights are its doubles bit for bit.
"""
import json
import sys

import h5py
import numpy as np


def text(v):
    return v.decode('utf-8') if isinstance(v, bytes) else str(v)


with h5py.File(sys.argv[1], 'r') as f:
    key = list(f['Data']['Surface'].keys())[0]
    obj = f['Data']['Surface'][key]
    no_data = obj.attrs['No Data'][0]
    unit = text(obj.attrs['Unit'][0])
    wavelength = float(obj.attrs['Wavelength'][0])
    scale_factor = float(obj.attrs['Interferometric Scale Factor'][0])
    obliquity = float(obj.attrs['Obliquity Factor'][0])
    dtype = str(obj.dtype)
    z = obj[()]
    z[z >= no_data] = np.nan
    attrs = f['Attributes'][list(f['Attributes'])[-1]].attrs
    resolution = float(attrs['Data Context.Data Attributes.Resolution:Value'][0])
    resolution_unit = text(attrs['Data Context.Data Attributes.Resolution:Unit'][0])
    title = text(obj.attrs['Title'][0]) if 'Title' in obj.attrs else ''

valid = ~np.isnan(z)
out = {'rows': z.shape[0], 'columns': z.shape[1], 'dtype': dtype, 'unit': unit,
       'no_data': float(no_data), 'wavelength_m': wavelength, 'scale_factor': scale_factor,
       'obliquity': obliquity, 'resolution': resolution, 'resolution_unit': resolution_unit,
       'title': title, 'valid': int(valid.sum()), 'min': float(z[valid].min()),
       'max': float(z[valid].max()), 'centre': float(z[z.shape[0] // 2, z.shape[1] // 2])}
if len(sys.argv) > 2:
    npy = np.load(sys.argv[2])
    out['same_as_npy'] = bool(npy.shape == z.shape and
                              np.array_equal(np.isnan(npy), np.isnan(z)) and
                              np.array_equal(npy[valid].view(np.uint64), z[valid].view(np.uint64)))
print(json.dumps(out))
