#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora, fuzz/corpus/<target>/, from the project's test data
(test/data, and shared/data where it is present) and a few inputs made here for what the data
lack (headerless matrices, pictures, small Klems files, an unfrozen octree and !xform lines that
name fuzz_util.h's part file). Only small files are taken: seeds are kept under 20 KB each and a
corpus under 200 KB, so that the regression runs (ctest -L fuzz) take seconds.

usage: fuzz/make_corpus.py [SHARED_DATA]   (default /work/shared/data; skipped if missing)
"""
import shutil
import struct
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEST = ROOT / "test" / "data"
SHARED = Path(sys.argv[1] if len(sys.argv) > 1 else "/work/shared/data")
PART = "/tmp/dayflux_fuzz_part.rad"  # fuzz_util.h's kPartFile
MAX_SEED = 20 * 1024
MAX_CORPUS = 200 * 1024


class Corpus:
    def __init__(self, name):
        self.dir = HERE / "corpus" / name
        shutil.rmtree(self.dir, ignore_errors=True)
        self.dir.mkdir(parents=True)
        self.size = 0

    def add(self, name, data):
        if isinstance(data, str):
            data = data.encode()
        if len(data) > MAX_SEED or self.size + len(data) > MAX_CORPUS:
            return
        (self.dir / name).write_bytes(data)
        self.size += len(data)

    def files(self, paths, prefix=""):
        for p in sorted(paths):
            if p.is_file() and p.stat().st_size <= MAX_SEED:
                self.add(prefix + p.name, p.read_bytes())


def shared(*parts):
    p = SHARED.joinpath(*parts)
    return [p] if p.is_file() else sorted(p.glob("*")) if p.is_dir() else []


def headerless(mode, cols, body):
    """An input of the matrix target without a header: its two bytes of spec, then the data."""
    return bytes([mode, cols]) + body


def picture(width, height, rle):
    """A RADIANCE picture: flat RGBE pixels, or scanlines in RADIANCE's run-length encoding."""
    head = b"#?RADIANCE\nEXPOSURE=2\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)
    data = b""
    for y in range(height):
        if not rle:
            data += b"".join(bytes([10 * x, 20 * y, 100, 129]) for x in range(width))
            continue
        data += bytes([2, 2, width >> 8, width & 255])
        for comp in range(4):
            value = [60 + y, 100, 200, 130][comp]
            data += bytes([128 + width, value]) if width < 128 else bytes([1, value] * width)
    return head + data


def matrix_corpus():
    c = Corpus("matrix")
    c.files((TEST / "matrix").glob("*.[mdf]mx"))
    c.files((TEST / "matrix").glob("*.mtx"))
    c.files((TEST / "radiance_util").glob("*"), "radiance_util_")
    c.add("picture_flat.hdr", picture(3, 2, False))
    c.add("picture_rle.hdr", picture(12, 3, True))
    ascii_rows = b"1 2 3 4 5 6\n7 8 9 10 11 12\n"
    c.add("noheader_ascii", headerless(0, 1, ascii_rows))
    c.add("noheader_ascii_1comp", headerless(4, 2, ascii_rows))
    c.add("noheader_float", headerless(1, 1, struct.pack("<12f", *range(12))))
    c.add("noheader_double_2rows", headerless(2 + 16, 0, struct.pack("<6d", *range(6))))
    c.add("noheader_picture", headerless(3 + 8, 2, b"-Y 1 +X 3\n" + bytes([1, 2, 3, 129] * 3)))
    c.add("big_endian.fmx", b"#?RADIANCE\nNROWS=1\nNCOLS=2\nNCOMP=1\nBigEndian=1\n"
          b"FORMAT=float\n\n" + struct.pack(">2f", 1.5, -2))
    c.add("resolution.mtx", b"#?RADIANCE\nFORMAT=ascii\nNCOMP=1\n\n-Y 2 +X 2\n1 2 3 4\n")


def scene_corpus(name, extra):
    c = Corpus(name)
    xform = [
        "void plastic black 0 0 5 0 0 0 0 0\n!xform -rz 90 -t 1 2 3 %s\n" % PART,
        "!xform -m black -n left -mx -s 2 -rx 30 -ry -45 %s\n" % PART,
        "!xform -e -c -n a %s %s\n" % (PART, PART),
    ]
    for i, text in enumerate(xform):
        c.add("xform%d.rad" % i, text)
    for i, text in enumerate(extra):
        c.add("made%d.rad" % i, text)
    return c


def scene_files():
    files = list((TEST / "scene" / "models").glob("*/*.rad"))
    files += (TEST / "scene" / "models").glob("*/*/*.rad")
    files += (TEST / "scene" / "skies").glob("*.rad")
    files += (TEST / "rfluxmtx" / "mirror").glob("*")
    files += (TEST / "rcontrib" / "office_open").glob("*.rad")
    files += (TEST / "rcontrib" / "bsdf_room").glob("*.rad")
    files += shared("radiance_tests", "renders")
    return [f for f in files if f.suffix in (".rad", ".mat")]


def scene_corpora():
    shapes = [
        # a polygon with a hole joined by a seam, as obj2rad and genbox users write them
        "void plastic w 0 0 5 .5 .5 .5 0 0\nw polygon holed 0 0 30\n"
        " 0 0 0 4 0 0 4 4 0 0 4 0 0 0 0 1 1 0 1 3 0 3 3 0 3 1 0 1 1 0\n",
        "void plastic w 0 0 5 .5 .5 .5 0 0\nw sphere s 0 0 4 0 0 0 1\n"
        "w cone c 0 0 8 0 0 0 0 0 1 1 .5\nw cylinder y 0 0 7 0 0 0 0 0 1 .5\n"
        "w ring r 0 0 8 0 0 0 0 0 1 .2 1\nw bubble b 0 0 4 0 0 0 1\n",
        'void brightfunc f 2 "x" . 0 0\nf mixfunc m 4 void void "a" . 0 0\nvoid alias a2 f\n',
    ]
    c = scene_corpus("scene", shapes)
    c.files(scene_files())
    a = scene_corpus("annotations", shapes[:1] + [
        "#@rfluxmtx h=u\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
        "#@rfluxmtx h=-r4 u=0,1,0 o=r%03d.hdr\nvoid glow g 0 0 4 1 1 1 0\n"
        "g ring r 0 0 8 0 0 0 0 0 -1 0 2\n",
        "#@rfluxmtx h=sc6\nvoid glow g 0 0 4 1 1 1 0\n#@rfluxmtx h=kf u=-Z\n"
        "g polygon p 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n",
    ])
    a.files(f for f in scene_files() if b"rfluxmtx" in f.read_bytes())


def octree_corpus():
    c = Corpus("octree")
    c.files((TEST / "scene").glob("*.oct"))
    c.files((TEST / "recipes" / "octrees").glob("*.oct"))
    c.files(shared("references", "rcontrib", "analytic.oct"))
    # An unfrozen octree listing the part file (five objects), with an empty octree.
    magic = struct.pack(">h", 4 * 8 + 251 + 4)
    strings = b"".join(s.encode() + b"\0" for s in ("-1", "-1", "-1", "4", PART, ""))
    c.add("unfrozen_part.oct", b"#?RADIANCE\noconv part.rad\nFORMAT=Radiance_octree\n\n" +
          magic + strings + struct.pack(">i", 5) + b"\0")


def mesh_corpus():
    c = Corpus("mesh")
    c.files((TEST / "scene" / "mesh").glob("*.rtm"))


def calcomp_corpus():
    c = Corpus("calcomp")
    c.files((ROOT / "lib").glob("*.cal"))
    c.add("made0.cal", "f(x, y) = if(x - y, x * y ^ 2, -y / 3); v = f(Dx, $5) + select(2, 1, 2);\n"
          "c : sqrt(2) * PI; PI : 3.14159265358979; r(n) = if(n, r(n - 1) + 1, 0); w = r(5);\n")
    c.add("made1.cal", "{ comment {nested} } a = max(1, 2, Dz) + min(Dx, Dy) + atan2(Dy, Dx);\n"
          "b = floor(rand(a)) + ceil(log10(abs2(3))) + arg(0) + arg(1); abs2(x) = if(x, x, -x);\n")
    # reinhart.cal wants MF first; its rbin is then computed directly (cal/direct_bins.h)
    c.add("reinhart_mf2.cal", "MF : 2;\n" + (ROOT / "lib" / "reinhart.cal").read_text())


def weather_corpus():
    c = Corpus("weather")
    c.files((TEST / "sky").glob("*.wea"))
    c.files((TEST / "sky" / "radiance_gen").glob("*.wea"), "radiance_gen_")
    c.files((p for p in shared("references", "gendaymtx") if p.suffix in (".wea", ".txt")), "ref_")
    for epw in [TEST / "sky" / "epw" / "NLD_Amsterdam.062400_IWEC.epw"] + \
            shared("weather", "USA_CO_Denver.Intl.AP.725650_TMY3.epw"):
        if epw.is_file():  # the header and the first day and a half
            lines = epw.read_bytes().split(b"\n")
            c.add(epw.stem + "_head.epw", b"\n".join(lines[:44]) + b"\n")
    c.files(shared("models", "subramaniam_tutorial", "room", "assets"))


def klems(structure, basis, blocks, values):
    """A Klems BSDF XML file with the given angle basis and data blocks of `values`."""
    body = "".join(
        "<WavelengthData><Wavelength unit=\"Integral\">Visible</Wavelength>"
        "<WavelengthDataBlock><WavelengthDataDirection>%s</WavelengthDataDirection>"
        "<ColumnAngleBasis>%s</ColumnAngleBasis><RowAngleBasis>%s</RowAngleBasis>"
        "<ScatteringDataType>BTDF</ScatteringDataType><ScatteringData>%s</ScatteringData>"
        "</WavelengthDataBlock></WavelengthData>\n" % (d, name, name, values)
        for d, name in blocks)
    return ("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<WindowElement xmlns=\"http://windows.lbl.gov\"><WindowElementType>System"
            "</WindowElementType><FileType>BSDF</FileType><Optical><Layer>\n"
            "<Material><Name>fuzz</Name></Material>\n"
            "<DataDefinition><IncidentDataStructure>%s</IncidentDataStructure>%s"
            "</DataDefinition>\n%s</Layer></Optical></WindowElement>\n" % (structure, basis, body))


def bsdf_corpus():
    c = Corpus("bsdf_xml")
    tiny = ("<AngleBasis><AngleBasisName>Tiny</AngleBasisName>"
            "<AngleBasisBlock><Theta>0</Theta><nPhis>1</nPhis><ThetaBounds><LowerTheta>0"
            "</LowerTheta><UpperTheta>30</UpperTheta></ThetaBounds></AngleBasisBlock>"
            "<AngleBasisBlock><Theta>60</Theta><nPhis>4</nPhis><ThetaBounds><LowerTheta>30"
            "</LowerTheta><UpperTheta>90</UpperTheta></ThetaBounds></AngleBasisBlock>"
            "</AngleBasis>")
    five = " ".join("%.3f" % (0.1 + 0.05 * i) for i in range(25))
    sides = [("Transmission Front", "Tiny"), ("Reflection Front", "Tiny"),
             ("Reflection Back", "Tiny"), ("Transmission Back", "Tiny")]
    c.add("tiny_columns.xml", klems("Columns", tiny, sides, five))
    c.add("tiny_rows.xml", klems("Rows", tiny, sides[:2], five))
    quarter = " ".join("%.2f" % (1.5 if i % 42 == 0 else 0.02) for i in range(41 * 41))
    c.add("klems_quarter.xml", klems("Columns", "",
                                     [("Transmission Front", "LBNL/Klems Quarter")], quarter))
    c.files(shared("radiance_tests", "util", "ref", "testBSDF.xml"))


def engine_corpus():
    """engine_fuzzer reads its input as choices (a byte each): any bytes make a run. The seeds
    are bytes of a fixed random stream, and the findings kept since (named for what they found)
    are left in place."""
    import random
    d = HERE / "corpus" / "engine"
    d.mkdir(parents=True, exist_ok=True)
    stream = random.Random(41)
    for i in range(24):
        size = stream.choice([16, 48, 96, 160, 256])
        (d / ("seed%02d" % i)).write_bytes(bytes(stream.randrange(256) for _ in range(size)))


def main():
    engine_corpus()
    matrix_corpus()
    scene_corpora()
    octree_corpus()
    mesh_corpus()
    calcomp_corpus()
    weather_corpus()
    bsdf_corpus()
    for d in sorted((HERE / "corpus").iterdir()):
        files = list(d.iterdir())
        print("%-12s %3d seeds %7d bytes" % (d.name, len(files),
                                              sum(f.stat().st_size for f in files)))


if __name__ == "__main__":
    main()
