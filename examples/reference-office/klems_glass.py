#!/usr/bin/env python3
"""Writes the Klems (LBNL full basis) BSDF of a RADIANCE `glass` pane, for dctimestep's T.

A clear pane scatters nothing: light entering through Klems patch i leaves through patch i on
the other side (the basis measures each side's angles from its own normal), so the transmission
matrix is diagonal, T[i][i] = tau(theta_i) / Lambda_i, with tau RADIANCE's angular transmission
of `glass` (src/rt/glass.c: Fresnel at both faces, the transmissivity to the power 1/cos of the
refracted angle, multiple reflections) at the patch's centre and Lambda_i the patch's projected
solid angle, pi (sin^2 theta_hi - sin^2 theta_lo) / nphi. Front and back are the same; the
reflection blocks hold the Fresnel reflection the same way (dctimestep uses only transmission).

usage: klems_glass.py [--transmissivity 0.7085] [--index 1.52] > clear.xml
"""
import argparse
import math
import sys

# LBNL/Klems Full: (centre theta, nphi, lower, upper) per ring, degrees.
KLEMS_FULL = [(0, 1, 0, 5), (10, 8, 5, 15), (20, 16, 15, 25), (30, 20, 25, 35), (40, 24, 35, 45),
              (50, 24, 45, 55), (60, 24, 55, 65), (70, 16, 65, 75), (82.5, 12, 75, 90)]


def glass(cos_i, transmissivity, n):
    """RADIANCE glass's (transmission, reflection) for incidence cosine cos_i (glass.c)."""
    cos2 = math.sqrt((1 - 1 / (n * n)) + cos_i * cos_i / (n * n))
    d = transmissivity ** (1 / cos2)
    r1e = ((cos_i - n * cos2) / (cos_i + n * cos2)) ** 2
    r1m = ((1 / cos_i - n / cos2) / (1 / cos_i + n / cos2)) ** 2
    t = 0.5 * (1 - r1e) ** 2 * d / (1 - r1e * r1e * d * d)
    t += 0.5 * (1 - r1m) ** 2 * d / (1 - r1m * r1m * d * d)
    dd = d * d
    r = 0.5 * r1e * (1 + (1 - 2 * r1e) * dd) / (1 - r1e * r1e * dd)
    r += 0.5 * r1m * (1 + (1 - 2 * r1m) * dd) / (1 - r1m * r1m * dd)
    return t, r


def diagonal(values):
    n = len(values)
    rows = []
    for j in range(n):
        rows.append(",".join(f"{values[i]:.6g}" if i == j else "0" for i in range(n)) + ",")
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--transmissivity", type=float, default=0.7085)
    ap.add_argument("--index", type=float, default=1.52)
    a = ap.parse_args()
    if not (0 < a.transmissivity < 1 and a.index > 1):
        sys.exit("klems_glass.py: the transmissivity must lie in (0, 1) and the index above 1")
    trans, refl = [], []
    for theta, nphi, lo, hi in KLEMS_FULL:
        lam = math.pi * (math.sin(math.radians(hi)) ** 2 - math.sin(math.radians(lo)) ** 2) / nphi
        t, r = glass(math.cos(math.radians(theta)), a.transmissivity, a.index)
        trans += [t / lam] * nphi
        refl += [r / lam] * nphi
    out = sys.stdout
    out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
    # (XML forbids "--" inside a comment: RADIANCE's parser refuses the file, so no option names)
    out.write(f"<!-- klems_glass.py: RADIANCE glass of transmissivity {a.transmissivity}, index "
              f"{a.index}, as a Klems BSDF -->\n")
    out.write('<WindowElement xmlns="http://windows.lbl.gov" '
              'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
              'xsi:schemaLocation="http://windows.lbl.gov/BSDF-v1.4.xsd">\n')
    out.write("<WindowElementType>System</WindowElementType>\n<FileType>BSDF</FileType>\n")
    out.write("<Optical>\n<Layer>\n\t<Material>\n\t\t<Name>clear glass</Name>\n"
              "\t\t<DeviceType>Other</DeviceType>\n"
              '\t\t<Thickness unit="meter">0</Thickness>\n\t</Material>\n')
    out.write("\t<DataDefinition>\n\t\t<IncidentDataStructure>Columns</IncidentDataStructure>\n"
              "\t\t<AngleBasis>\n\t\t\t<AngleBasisName>LBNL/Klems Full</AngleBasisName>\n")
    for theta, nphi, lo, hi in KLEMS_FULL:
        out.write(f"\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>{theta}</Theta>\n"
                  f"\t\t\t\t<nPhis>{nphi}</nPhis>\n\t\t\t\t<ThetaBounds>\n"
                  f"\t\t\t\t\t<LowerTheta>{lo}</LowerTheta>\n"
                  f"\t\t\t\t\t<UpperTheta>{hi}</UpperTheta>\n"
                  "\t\t\t\t</ThetaBounds>\n\t\t\t</AngleBasisBlock>\n")
    out.write("\t\t</AngleBasis>\n\t</DataDefinition>\n")
    for direction, values, kind in (("Transmission Front", trans, "BTDF"),
                                    ("Transmission Back", trans, "BTDF"),
                                    ("Reflection Front", refl, "BRDF"),
                                    ("Reflection Back", refl, "BRDF")):
        out.write("\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n"
                  '\t\t<Wavelength unit="Integral">Visible</Wavelength>\n'
                  "\t\t<SourceSpectrum>CIE Illuminant D65 1nm.ssp</SourceSpectrum>\n"
                  "\t\t<DetectorSpectrum>ASTM E308 1931 Y.dsp</DetectorSpectrum>\n"
                  "\t\t<WavelengthDataBlock>\n"
                  f"\t\t\t<WavelengthDataDirection>{direction}</WavelengthDataDirection>\n"
                  "\t\t\t<ColumnAngleBasis>LBNL/Klems Full</ColumnAngleBasis>\n"
                  "\t\t\t<RowAngleBasis>LBNL/Klems Full</RowAngleBasis>\n"
                  f"\t\t\t<ScatteringDataType>{kind}</ScatteringDataType>\n"
                  "\t\t\t<ScatteringData>\n")
        out.write(diagonal(values) + "\n")
        out.write("\t\t\t</ScatteringData>\n\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n")
    out.write("</Layer>\n</Optical>\n</WindowElement>\n")


if __name__ == "__main__":
    main()
