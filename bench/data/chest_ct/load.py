import os, sys, numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__))); from dcm import read_dcm, pixels
def load_series(d):
    sl=[]
    for f in os.listdir(d):
        i,b=read_dcm(os.path.join(d,f))
        z=float(i['ImagePositionPatient'].split('\\')[2])
        sl.append((z,pixels(i,b),i,f))
    sl.sort(key=lambda t:t[0])          # ascending patient z (inferior -> superior)
    vol=np.stack([s[1] for s in sl]).astype(np.float32)
    return vol, [s[0] for s in sl], [s[2] for s in sl], [s[3] for s in sl]
