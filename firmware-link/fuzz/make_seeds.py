#!/usr/bin/env python3
"""Write seed inputs for the fuzz targets into corpus/<target>/ (valid frames
of each protocol, so that mutations get past the checksums early).

Usage (from firmware-link/fuzz): python3 make_seeds.py
"""
import os
import struct


def crc32c(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


assert crc32c(b"123456789") == 0xE3069283


def cobs(data):
    out, block = bytearray(), bytearray()
    for b in data:
        if b == 0:
            out.append(len(block) + 1)
            out += block
            block = bytearray()
        else:
            block.append(b)
            if len(block) == 254:
                out.append(255)
                out += block
                block = bytearray()
    out.append(len(block) + 1)
    out += block
    return bytes(out)


def link(seq, kind, payload):
    raw = bytes([1]) + struct.pack("<H", seq) + bytes([kind]) + payload
    raw += struct.pack("<I", crc32c(raw))
    return cobs(raw) + b"\0"


def pelco(a, c1, c2, d1, d2):
    return bytes([0xFF, a, c1, c2, d1, d2, (a + c1 + c2 + d1 + d2) & 255])


def enttec(label, data):
    return bytes([0x7E, label, len(data) & 255, len(data) >> 8]) + data + b"\xe7"


def write(target, items):
    d = f"corpus/{target}"
    os.makedirs(d, exist_ok=True)
    for i, s in enumerate(items):
        with open(f"{d}/seed{i}", "wb") as f:
            f.write(s)


head = struct.pack("<iiiiB", 1, 2, 3, 4, 1)
links = [
    link(1, 0x01, struct.pack("<ii", 100000, -5000)), link(2, 0x02, struct.pack("<ii", -3, 7)),
    link(3, 0x03, b""), link(4, 0x04, b""), link(5, 0x05, struct.pack("<II", 500000, 100)),
    link(6, 0x06, b""), link(7, 0x10, b"\x02"), link(8, 0x11, b""), link(9, 0x20, b"\x01\xff\x7f"),
    link(10, 0x21, b""), link(11, 0x22, b""), link(12, 0x30, b""), link(13, 0x31, b""),
    link(14, 0x81, head), link(15, 0x8F, b"\x01\x01"), link(16, 0xC3, b""), link(17, 0xC1, head),
]
write("link_frame", links + [b"".join(links)])
write("link_device", links + [b"".join(links[:8])])
pel = [pelco(1, 0, 0, 0, 0), pelco(0x0A, 0x88, 0x90, 0, 0x20), pelco(1, 0, 0x4B, 0x23, 0x28),
       pelco(1, 0, 0x4D, 0x88, 0xB8), pelco(1, 0, 0x51, 0, 0), pelco(1, 0, 0x53, 0, 0), pelco(1, 0, 3, 0, 1),
       pelco(1, 0, 7, 0, 1), pelco(1, 0, 2, 0x20, 0), pelco(1, 0, 0x59, 0x46, 0x50)]
write("pelco_d", pel + [b"".join(pel)])
write("pelco_d_device", pel + [b"".join(pel)])
write("flir_reply", [b"*\r\n", b"* 22\r\n", b"PP * Current Pan position is -2500\r\n", b"!P\r\n!T\r\n!D\r\n",
                     b"! Maximum allowable Pan position is 3090\r\n", b"* 185.1428\r\n"])
write("flir_device", [b"PP ", b"ED FT PP-2500 A PP ", b"LD TP5000 A ", b"PS1000 PA2000 PR TR PN PX TN TX ",
                      b"TO100 PO-100 H R ", b"FV EE L "])
ent = [enttec(6, bytes([0, 255, 128, 0])), enttec(10, b""), enttec(3, b"\0\0"), enttec(6, bytes(513))]
write("enttec", ent + [b"".join(ent)])
write("enttec_device", ent + [b"".join(ent)])
fw = [b"pos=3\r", b"pos?\r", b"pcount?\r", b"*idn?\r", b"pos=9\r"]
write("fw102c_device", fw + [b"".join(fw)])
write("fw102c_response", [b"pos?\r4\r>", b"pos=9\rCommand error CMD_ARG_INVALID\r>", b"pos=2\r>"])
