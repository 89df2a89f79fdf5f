#!/usr/bin/python3
"""What a checkpoint holds: the size of each section of a checkpoint.bin (or final_state.bin).

  checkpoint_sections.py DIR/checkpoint.bin

A checkpoint is the run's state written section by section, each opened by its tag (a
length-prefixed name: the particles and neighbour list under `dynamics`, the integrator, the
observers' accumulators: `rheology`, `pressure_cell`, `profiles`, `diffusion_samples`, and the
diffusion analysis's `correlator`s and `increment_gram`); the bytes up to the first tag are the
header and the resolved configuration. Prints each section's offset and size in MB, in file
order (docs/sweeps.md, "Points longer than a sitting").
"""
import re
import struct
import sys

# A tag: its name's length as a little-endian 64-bit integer (4 to 40), then exactly that many
# bytes of name. The name is read by its length, not by the letters that follow: the section's
# first byte may itself be a lowercase letter.
LENGTH = re.compile(rb"(?=([\x04-\x28])\x00{7})")
NAME = re.compile(rb"[a-z_]+")


def sections(data):
    found = []
    for m in LENGTH.finditer(data):
        (length,) = struct.unpack("<Q", data[m.start():m.start() + 8])
        name = data[m.start() + 8:m.start() + 8 + length]
        if len(name) == length and NAME.fullmatch(name):
            found.append((m.start(), name.decode()))
    return found


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    with open(argv[1], "rb") as f:
        data = f.read()
    tags = sections(data)
    if not tags:
        sys.exit(f"{argv[1]}: no section tags found (not a sheardiff checkpoint?)")
    starts = [(0, "(header and configuration)")] + tags
    print(f"{argv[1]}: {len(data) / 1e6:.3f} MB")
    print(f"{'offset':>10}  {'MB':>7}  section")
    for k, (start, name) in enumerate(starts):
        end = starts[k + 1][0] if k + 1 < len(starts) else len(data)
        print(f"{start:>10}  {(end - start) / 1e6:7.3f}  {name}")


if __name__ == "__main__":
    main(sys.argv)
