// The BSDF material where a ray meets it (a fragment: see language.h): m_bsdf()'s local frame
// from the front normal and the up vector, the view direction in it and the BSDF's resolution
// there, and direct_specular_OK() toward a source.
#ifdef DAYFLUX_BSDF

// The thickness and the up vector of BSDF b where a ray meets it (its variables those of the
// front normal): constants, or patterns of the ray.
real BsdfThickness(int b, IN(Ray) r, real3 point, real3 front_normal, real t) {
    int p = KlemsInt(b + kKlemsThicknessPattern);
    if (p < 0) return real(klems[b + kKlemsThickness]);
    SetRayVariables(r, point, front_normal, t);
    return real(PatternRGB(p).x);
}
real3 BsdfUp(int b, IN(Ray) r, real3 point, real3 front_normal, real t) {
    int p = KlemsInt(b + kKlemsUpPattern);
    if (p < 0) return real3(klems[b + kKlemsUp], klems[b + kKlemsUp + 1], klems[b + kKlemsUp + 2]);
    SetRayVariables(r, point, front_normal, t);
    return real3(PatternRGB(p));
}

// m_bsdf()'s frame where a ray meets a BSDF surface: z the front normal, x = up x z, and the view
// direction (toward where the ray came from) in it.
struct BsdfFrame {
    real3 x, y, z;
    real3 view;
};
real3 ToLocal(IN(BsdfFrame) f, real3 w) {
    return normalize(real3(dot(f.x, w), dot(f.y, w), dot(f.z, w)));
}
real3 ToWorld(IN(BsdfFrame) f, real3 l) { return normalize(f.x * l.x + f.y * l.y + f.z * l.z); }
// False when the up vector is parallel to the normal.
bool MakeBsdfFrame(real3 up, real3 front_normal, real3 raydir, OUT(BsdfFrame) f) {
    f.z = normalize(front_normal);
    real3 x = cross(up, f.z);
    if (dot(x, x) == 0.) return false;
    f.x = normalize(x);
    f.y = cross(f.z, f.x);
    f.view = ToLocal(f, -raydir);
    return true;
}
// bsdf_jitter(): view direction `view` moved within +-size/2 (times -ss below 1).
real3 KJitter(real3 view, real size, real u, real v) {
    if (params.ss < 1.) size *= params.ss;
    if (size <= 1e-6) return view;
    return normalize(view + real3(size * (.5 - u), size * (.5 - v), 0));
}

#ifdef DAYFLUX_APERTURE
// compute_through() for aBSDF: where the transmission for a ray met on side `front` peaks about
// its straight-through direction, the peak's value times its projected solid angle (through) and
// the mean BTDF around it (surround), both grey and before the pattern; 0 where there is no such
// peak (or the pattern is black there). kview: the view direction in the BSDF's frame. Of 29
// directions about the straight-through one, a smallest patch apart, those of distinct values,
// brightest first, join the peak while their patches are that small and their value is above an
// eighth of the peak's mean; the rest are the surround.
void ComputeThrough(int b, real3 kview, bool front, bool pattern_lit, OUT(real) through,
                    OUT(real) surround) {
    through = 0.;
    surround = 0.;
    int q = PartT(b, front);
    if (q < 0 || !pattern_lit) return;
    real min_psa = real(klems[q + kPartMinProjSA]), srchrad = sqrt(min_psa);
    real3 dirs[29];
    real values[29];
    DONT_UNROLL for (int i = 0; i < 29; ++i) {
        // RADIANCE's dir2check: the centre, then the 8 neighbours at 0.6, 1.2 and 1.8 and the 4
        // on the axes at 2.4 (floats, as it keeps them)
        int ring = (i + 7) / 8;
        int k = i == 0 ? 0 : (i - 1) % 8;
        real offset = real(ring == 1   ? float(0.6)
                           : ring == 2 ? float(1.2)
                           : ring == 3 ? float(1.8)
                                       : float(2.4));
        real2 d = k == 0   ? real2(-1, 0)
                  : k == 1 ? real2(0, 1)
                  : k == 2 ? real2(0, -1)
                  : k == 3 ? real2(1, 0)
                  : k == 4 ? real2(-1, 1)
                  : k == 5 ? real2(-1, -1)
                  : k == 6 ? real2(1, 1)
                           : real2(1, -1);
        if (i == 0) d = real2(0);
        real3 tdir = normalize(
            real3(-kview.x + d.x * offset * srchrad, -kview.y + d.y * offset * srchrad, -kview.z));
        real value = KlemsEval(b, kview, tdir);
        // insertion: brightest first, the earlier of equal values first (a stable sort)
        int at = i;
        while (at > 0 && values[at - 1] < value) {
            values[at] = values[at - 1];
            dirs[at] = dirs[at - 1];
            --at;
        }
        values[at] = value;
        dirs[at] = tdir;
    }
    if (values[0] <= kTiny) return;
    real peak = 0., peak_sum = 0., peak_omega = 0., surround_sum = 0., surround_omega = 0.;
    int ns = 0;
    DONT_UNROLL for (int i = 0; i < 29; ++i) {
        if (i > 0 && values[i] == values[i - 1]) continue;  // the same patch, assumed
        real tomega = SizeMin(b, kview, dirs[i]);
        if (tomega > 1.5 * min_psa || peak_sum > 8. * values[i] * real(ns)) {
            if (i == 0) return;
            surround_sum += values[i] * tomega;
            surround_omega += tomega;
            continue;
        }
        peak += values[i] * tomega;
        peak_omega += tomega;
        peak_sum += values[i];
        ++ns;
    }
    if (surround_omega <= kTiny) return;  // no surround, no peak
    if ((peak_sum / real(ns) - KlemsLambertian(b, true, kview.z > 0.) / kPi) * peak_omega < .0005)
        return;  // below 0.05 % transmission
    through = peak;
    surround = surround_sum / surround_omega;
}
#endif

// direct_specular_OK(): the non-diffuse BSDF toward a source (world direction, of solid angle
// omega), averaged over 4 x ss x weight jittered views; -1 when none is to be added. Through an
// aBSDF's peak (through: it has one; `front` the side its ray met), near enough the
// straight-through direction, the surround given instead (and at_surround set).
real DirectSpecular(int b, IN(BsdfFrame) f, real3 source_dir, real weight, real omega, bool through,
                    bool front, real surround, OUT(bool) at_surround) {
    at_surround = false;
    real3 vsrc = ToLocal(f, source_dir), kview = f.view;
    bool sf = vsrc.z > 0., vf = kview.z > 0.;
    real lamb;
    if (sf == vf) {
        if (PartR(b, vf) < 0) return -1.;
        lamb = KlemsLambertian(b, false, vf);
    } else {
        if (!HasTransmission(b)) return -1.;
        lamb = KlemsLambertian(b, true, vf);
    }
#ifdef DAYFLUX_APERTURE
    if (sf != vf && through) {  // the peak's light comes through unscattered: not counted here
        real dx = vsrc.x + kview.x, dy = vsrc.y + kview.y;
        real min_psa = real(klems[PartT(b, front) + kPartMinProjSA]);
        real tomega = omega * abs(vsrc.z);
        if (dx * dx + dy * dy <=
            (2.5 * 4. / kPi) * (tomega + min_psa + 2. * sqrt(tomega * min_psa))) {
            at_surround = true;  // (the caller weighs it by the pattern)
            return surround;
        }
    }
#endif
    real diffuse = lamb > 1e-6 ? lamb / kPi : 0.;
    real tomega = 0., tsr = 0., sum = 0.;
    int nsamp = 1, count = 0;
    // i = -1: the view's own size (one SizeMin call)
    DONT_UNROLL for (int i = -1; i < nsamp; ++i) {
        real3 vjit = kview;
        if (i >= 0) {
            real u = Rand(), v = Rand();
            vjit = KJitter(kview, tsr, u, v);
        }
        real size = SizeMin(b, vjit, vsrc);
        if (i < 0) {
            tomega = size;
            tsr = sqrt(tomega);
            if (tsr > 0.) nsamp = max(1, int(4. * params.ss * weight + .5));
            continue;
        }
        if (size < .12 * tomega) continue;  // a finer patch: not safe to include
        real f = KlemsEval(b, vjit, vsrc);
        if (f - diffuse <= 1e-6) continue;
        sum += f;
        ++count;
    }
    if (count == 0) return -1.;
    return max(0., sum / real(count) - diffuse);
}

#endif  // DAYFLUX_BSDF
