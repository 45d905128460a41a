import struct, numpy as np, sys
LONG_VR = {b'OB',b'OW',b'OF',b'SQ',b'UT',b'UN',b'OD',b'OL',b'UC',b'UR',b'OV'}
TAGS = {(0x0008,0x0060):'Modality',(0x0028,0x0010):'Rows',(0x0028,0x0011):'Columns',(0x0028,0x0030):'PixelSpacing',
        (0x0018,0x0050):'SliceThickness',(0x0020,0x0032):'ImagePositionPatient',(0x0020,0x0037):'ImageOrientationPatient',
        (0x0028,0x0100):'BitsAllocated',(0x0028,0x0103):'PixelRepresentation',(0x0028,0x1052):'RescaleIntercept',
        (0x0028,0x1053):'RescaleSlope',(0x0002,0x0010):'TransferSyntaxUID',(0x0020,0x0013):'InstanceNumber',
        (0x0008,0x103e):'SeriesDescription',(0x0008,0x1030):'StudyDescription',(0x0018,0x0015):'BodyPartExamined',
        (0x0008,0x0070):'Manufacturer',(0x0028,0x0002):'SamplesPerPixel',(0x0018,0x0088):'SpacingBetweenSlices',
        (0x0018,0x0060):'KVP',(0x0020,0x000e):'SeriesInstanceUID',(0x0018,0x1210):'ConvolutionKernel',(0x0028,0x0004):'Photometric'}
def read_dcm(path_or_bytes):
    b = path_or_bytes if isinstance(path_or_bytes,bytes) else open(path_or_bytes,'rb').read()
    assert b[128:132]==b'DICM'
    pos=132; out={}; explicit=True
    while pos < len(b)-8:
        grp,el = struct.unpack('<HH',b[pos:pos+4])
        if grp!=0x0002 and out.get('TransferSyntaxUID','').startswith('1.2.840.10008.1.2') and out['TransferSyntaxUID'].strip('\0 ')=='1.2.840.10008.1.2':
            explicit=False
        vr=b[pos+4:pos+6]
        if explicit and vr.isalpha() and vr.isupper():
            if vr in LONG_VR:
                ln=struct.unpack('<I',b[pos+8:pos+12])[0]; hdr=12
            else:
                ln=struct.unpack('<H',b[pos+6:pos+8])[0]; hdr=8
        else:
            vr=None; ln=struct.unpack('<I',b[pos+4:pos+8])[0]; hdr=8
        if (grp,el)==(0x7fe0,0x0010):
            out['_pixel_offset']=pos+hdr; out['_pixel_len']=ln; break
        if ln==0xFFFFFFFF:  # undefined length sequence: skip to sequence delimiter
            end=b.find(b'\xfe\xff\xdd\xe0\x00\x00\x00\x00',pos+hdr)
            pos=end+8; continue
        val=b[pos+hdr:pos+hdr+ln]
        name=TAGS.get((grp,el))
        if name:
            if name in ('Rows','Columns','BitsAllocated','PixelRepresentation','SamplesPerPixel'):
                out[name]=struct.unpack('<H',val[:2])[0]
            else:
                out[name]=val.decode('latin1').strip('\0 ')
        pos+=hdr+ln
    return out, b
def pixels(info,b):
    assert info['TransferSyntaxUID'] in ('1.2.840.10008.1.2','1.2.840.10008.1.2.1'), info['TransferSyntaxUID']
    dt = '<i2' if info.get('PixelRepresentation',0)==1 else '<u2'
    assert info['BitsAllocated']==16
    n=info['Rows']*info['Columns']
    a=np.frombuffer(b,dtype=dt,count=n,offset=info['_pixel_offset']).reshape(info['Rows'],info['Columns'])
    return a.astype(np.float32)*float(info.get('RescaleSlope',1) or 1)+float(info.get('RescaleIntercept',0) or 0)
if __name__=='__main__':
    for p in sys.argv[1:]:
        i,b=read_dcm(p); print(p,{k:v for k,v in i.items()})
