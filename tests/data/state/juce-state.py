import re, struct, sys
ALPHA = ".ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+"
def b64dec(s):
    size, data = s.split('.', 1)
    size = int(size); out = bytearray(size); pos = 0
    for ch in data:
        v = ALPHA.index(ch)
        for b in range(6):
            if pos + b < size*8 and (v >> b) & 1: out[(pos+b)//8] |= 1 << ((pos+b) % 8)
        pos += 6
    return bytes(out)
def b64enc(data):
    nbits = len(data)*8; out = []; pos = 0
    while pos < nbits:
        v = 0
        for b in range(6):
            if pos + b < nbits and (data[(pos+b)//8] >> ((pos+b) % 8)) & 1: v |= 1 << b
        out.append(ALPHA[v]); pos += 6
    return f"{len(data)}." + "".join(out)
def outer(path):
    d = open(path,'rb').read()
    magic, size = struct.unpack('<II', d[:8]); return d[8:8+size].rstrip(b'\0').decode()
def inner_of(outer_xml):
    m = re.search(r'<IComponent>([^<]*)</IComponent>', outer_xml); blob = b64dec(m.group(1))
    magic, size = struct.unpack('<II', blob[:8]); return blob[8:8+size].rstrip(b'\0').decode()
def rebuild(outer_xml, inner_xml):
    t = inner_xml.encode() + b'\0'
    blob = struct.pack('<II', 0x21324356, len(t)) + t
    o = re.sub(r'<IComponent>[^<]*</IComponent>', '<IComponent>' + b64enc(blob) + '</IComponent>', outer_xml)
    ot = o.encode() + b'\0'
    return struct.pack('<II', 0x21324356, len(ot)) + ot
if __name__ == '__main__':
    print(inner_of(outer(sys.argv[1])))
