// Klems BSDF data as RADIANCE's BSDF library reads it (a fragment: see language.h):
// SDevalBSDF, SDdirectHemi, SDsizeBSDF and SDsampComponent on matrix data, over the klems table
// (tables.h's kKlems*, kPart*, kBasis* layout), which is all they need. Directions are in the
// BSDF's local frame (z along the surface's front normal) and point away from the surface,
// toward where light comes from or goes to. (On the GPU code size matters here: the compiler
// inlines every call, so these functions call each other from as few places as they can.)
#ifdef DAYFLUX_BSDF

int KlemsInt(int at) { return int(klems[at]); }

// The patch of local direction w in a basis (slot: kPartInBasis or kPartOutBasis of part q,
// with `rings` rings); -1 outside it.
int BasisIndex(int q, int slot, int rings, real3 w) {
    if (w.z < 0. || w.z > 1.00001) return -1;
    int cosat = KlemsInt(q + slot + kBasisCosines), nphiat = KlemsInt(q + slot + kBasisAzimuths),
        firstat = KlemsInt(q + slot + kBasisFirst);
    if (w.z < real(klems[cosat + rings])) return -1;
    int ring = 0;
    while (ring + 1 < rings && w.z <= real(klems[cosat + ring + 1])) ++ring;
    real azi = degrees(atan(w.y, w.x));
    if (azi < 0.) azi += 360.0;
    int nphi = KlemsInt(nphiat + ring);
    int ndx = int(azi / 360.0 * real(nphi) + 0.5);
    if (ndx >= nphi) ndx = 0;
    return KlemsInt(firstat + ring) + ndx;
}
// A direction in the frame of a basis on the front (the incident one pointing away from the
// surface on its side).
real3 ToFrontOut(bool incident, bool front, real3 v) {
    return real3(incident ? -v.x : v.x, incident ? -v.y : v.y, front ? v.z : -v.z);
}
// The patch of direction v in part q's incident (or outgoing) basis.
int PartIndex(int q, real3 v, bool incident) {
    return BasisIndex(
        q, incident ? kPartInBasis : kPartOutBasis,
        KlemsInt(q + (incident ? kPartInRings : kPartOutRings)),
        ToFrontOut(incident, klems[q + (incident ? kPartInFront : kPartOutFront)] > 0.5, v));
}
real PartSolidAngle(int q, int i, bool incident) {
    return i < 0 ? -1.0
                 : real(klems[KlemsInt(q + (incident ? kPartInBasis : kPartOutBasis) +
                                       kBasisSolidAngles) +
                              i]);
}
real KlemsValue(int q, int o, int i) {
    return real(klems[KlemsInt(q + kPartValues) + o * KlemsInt(q + kPartInSize) + i]);
}
// The part serving reflection on a side, and transmission arriving on a side (the other
// side's, reciprocally, where that side has none); -1 if none.
int PartR(int b, bool front) { return KlemsInt(b + kKlemsParts + (front ? 0 : 1)); }
int PartT(int b, bool front) {
    int own = KlemsInt(b + kKlemsParts + (front ? 2 : 3)),
        other = KlemsInt(b + kKlemsParts + (front ? 3 : 2));
    return own >= 0 ? own : other;
}
bool HasTransmission(int b) {
    return KlemsInt(b + kKlemsParts + 2) >= 0 || KlemsInt(b + kKlemsParts + 3) >= 0;
}
// The Lambertian total of reflection (or transmission) for light arriving on a side.
real KlemsLambertian(int b, bool transmission, bool front) {
    return real(klems[b + kKlemsLambertian + (transmission ? 2 : 0) + (front ? 0 : 1)]);
}

// SDevalBSDF: the BSDF (1/sr) for light between inv and outv, Lambertian part included.
real KlemsEval(int b, real3 inv, real3 outv) {
    bool fi = inv.z > 0., fo = outv.z > 0.;
    real value = KlemsLambertian(b, fi != fo, fi) / kPi;
    int q = fi == fo ? PartR(b, fi) : PartT(b, fi);
    if (q < 0) return value;
    int idx[2];
    DONT_UNROLL for (int k = 0; k < 4; ++k) {  // in, out; then, by reciprocity, the two swapped
        if (k == 2 && (idx[0] >= 0 || idx[1] >= 0)) break;
        idx[k & 1] = PartIndex(q, (k == 0 || k == 3) ? inv : outv, (k & 1) == 0);
    }
    int i = idx[0], o = idx[1];
    return i < 0 || o < 0 ? value : value + KlemsValue(q, o, i);
}

// The row of part q's cumulative distribution for incident direction inv (by reciprocity the
// outgoing one where inv is not incident there); its length; false if none.
bool CdfRow(int q, real3 inv, OUT(int) row, OUT(int) len, OUT(bool) reverse) {
    int nin = KlemsInt(q + kPartInSize), nout = KlemsInt(q + kPartOutSize);
    row = -1;
    len = 0;
    reverse = false;
    DONT_UNROLL for (int k = 0; k < 2 && row < 0; ++k) {
        int i = PartIndex(q, inv, k == 0);
        if (i < 0) continue;
        reverse = k == 1;
        len = reverse ? nin : nout;
        row = KlemsInt(q + (reverse ? kPartReverseCdf : kPartCdf)) + i * (len + 1);
    }
    return row >= 0;
}

// SDdirectHemi for the non-diffuse part of reflection or transmission.
real SpecularHemi(int b, real3 inv, bool xmit) {
    bool front = inv.z > 0.;
    int q = xmit ? PartT(b, front) : PartR(b, front);
    int row, len;
    bool reverse;
    if (q < 0 || !CdfRow(q, inv, row, len, reverse)) return 0.;
    return real(klems[row + len]);
}

// SDsizeBSDF over parts: psa.x the smallest patch met, psa.y (minmax) the largest.
void QueryProjSA(int q, real3 v1, real3 v2, bool same, bool minmax, INOUT(real2) psa) {
    real p[2];
    DONT_UNROLL for (int k = 0; k < 4; ++k) {
        if (k == 2 && (same || p[0] > 0. || p[1] > 0.)) break;
        bool incident = k == 1 || k == 2;
        real3 v = (k == 0 || k == 2) ? v1 : v2;
        p[k & 1] = PartSolidAngle(q, PartIndex(q, v, incident), incident);
    }
    if (minmax) {
        psa.y = max(psa.y, max(p[0], p[1]));
    }
    DONT_UNROLL for (int k = 0; k < 2; ++k) {
        if (p[k] > 0. && p[k] < psa.x) psa.x = p[k];
    }
}

// SDsizeBSDF with SDqueryMin+SDqueryMax for one direction.
real2 SizeMinMax(int b, real3 v) {
    bool front = v.z > 0.;
    real2 psa = real2(10, 0);
    bool any = false;
    DONT_UNROLL for (int k = 0; k < 2; ++k) {
        int q = k == 0 ? PartR(b, front) : PartT(b, front);
        if (q < 0) continue;
        QueryProjSA(q, v, v, true, true, psa);
        any = true;
    }
    if (!any) psa = real2(kPi);
    if (psa.x > psa.y) psa.x = psa.y;
    return psa;
}

// SDsizeBSDF with SDqueryMin for a pair of directions.
real SizeMin(int b, real3 v1, real3 v2) {
    bool front = v1.z > 0.;
    int q = (v1.z > 0.) != (v2.z > 0.) ? PartT(b, front) : PartR(b, front);
    if (q < 0) return kPi;
    real2 psa = real2(10, 0);
    QueryProjSA(q, v1, v2, false, false, psa);
    return psa.x;
}

// SDsampComponent: part q's hemispherical total for inv, and outv drawn from its distribution
// (rnd picks the patch, u and v the place in it). Returns 0 (outv 0) when there is nothing to
// sample.
real KlemsSample(int q, real3 inv, real rnd, real u, real v, OUT(real3) outv) {
    int row, len;
    bool reverse;
    outv = real3(0);
    if (!CdfRow(q, inv, row, len, reverse)) return 0.;
    real total = real(klems[row + len]);
    if (total <= 1e-6) return 0.;
    real target = clamp(rnd, 0.0, 1.0) * total;
    int lo = 0, hi = len - 1;  // the first patch whose cumulative end exceeds target
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (real(klems[row + mid + 1]) > target)
            hi = mid;
        else
            lo = mid + 1;
    }
    // The patch is in the outgoing basis, or by reciprocity the incident one.
    int slot = reverse ? kPartInBasis : kPartOutBasis;
    int rings = KlemsInt(q + (reverse ? kPartInRings : kPartOutRings));
    int firstat = KlemsInt(q + slot + kBasisFirst);
    int ring = 0;
    while (ring + 1 < rings && lo >= KlemsInt(firstat + ring + 1)) ++ring;
    int index = lo - KlemsInt(firstat + ring);
    real c0 = real(klems[KlemsInt(q + slot + kBasisCosines) + ring]),
         c1 = real(klems[KlemsInt(q + slot + kBasisCosines) + ring + 1]);
    real cz = sqrt((1. - u) * c0 * c0 + u * c1 * c1);
    real azi = 2. * kPi * (real(index) + v - .5) /
               real(KlemsInt(KlemsInt(q + slot + kBasisAzimuths) + ring));
    real sz = sqrt(max(0., 1. - cz * cz));
    outv = ToFrontOut(reverse, klems[q + (reverse ? kPartInFront : kPartOutFront)] > 0.5,
                      real3(cos(azi) * sz, sin(azi) * sz, cz));
    return total;
}

#endif  // DAYFLUX_BSDF
