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

// m_bsdf()'s frame where a ray meets a BSDF surface: z the front normal, x = up x z, the view
// direction (toward where the ray came from) in it, and the BSDF's resolution about it (sqrt of
// the smallest and largest projected solid angles).
real3 kx, ky, kz, kview;
real2 ksr;
real3 ToLocal(real3 w) { return normalize(real3(dot(kx, w), dot(ky, w), dot(kz, w))); }
real3 ToWorld(real3 l) { return normalize(kx * l.x + ky * l.y + kz * l.z); }
// False when the up vector is parallel to the normal.
bool KlemsFrame(real3 up, real3 front_normal, real3 raydir) {
    kz = normalize(front_normal);
    real3 x = cross(up, kz);
    if (dot(x, x) == 0.) return false;
    kx = normalize(x);
    ky = cross(kz, kx);
    kview = ToLocal(-raydir);
    return true;
}
// bsdf_jitter(): the view direction moved within +-size/2 (times -ss below 1).
real3 KJitter(real size, real u, real v) {
    if (SS < 1.) size *= SS;
    if (size <= 1e-6) return kview;
    return normalize(kview + real3(size * (.5 - u), size * (.5 - v), 0));
}

// direct_specular_OK(): the non-diffuse BSDF toward a source (world direction), averaged over
// 4 x ss x weight jittered views; -1 when none is to be added.
real DirectSpecular(int b, real3 source_dir, real weight) {
    real3 vsrc = ToLocal(source_dir);
    bool sf = vsrc.z > 0., vf = kview.z > 0.;
    real lamb;
    if (sf == vf) {
        if (PartR(b, vf) < 0) return -1.;
        lamb = KlemsLambertian(b, false, vf);
    } else {
        if (!HasTransmission(b)) return -1.;
        lamb = KlemsLambertian(b, true, vf);
    }
    real diffuse = lamb > 1e-6 ? lamb / kPi : 0.;
    real tomega = 0., tsr = 0., sum = 0.;
    int nsamp = 1, count = 0;
    // i = -1: the view's own size (one SizeMin call)
    DONT_UNROLL for (int i = -1; i < nsamp; ++i) {
        real3 vjit = kview;
        if (i >= 0) {
            real u = Rand(), v = Rand();
            vjit = KJitter(tsr, u, v);
        }
        real size = SizeMin(b, vjit, vsrc);
        if (i < 0) {
            tomega = size;
            tsr = sqrt(tomega);
            if (tsr > 0.) nsamp = max(1, int(4. * SS * weight + .5));
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
