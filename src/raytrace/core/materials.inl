// What each material does with a ray that reached it (a fragment: see language.h): RADIANCE's
// m_light(), m_clip(), m_normal() (plastic, metal, trans, pure or Gaussian specular), m_glass(),
// m_dielectric(), m_mirror() (with its substitute and the relay of shadow rays toward sources'
// images), raymixture() (mixfunc), m_bsdf() (Klems data), and rcontrib's -i.

// Where a ray is shaded, as the materials read it (RADIANCE's rop, ron, rod, rot, and its SP_FLAT
// flag): made once by Shade from what the ray met.
struct ShadingPoint {
    real3 point;
    real3 normal;  // the surface's, turned to face the ray
    real rod;      // the cosine between normal and the ray's reverse (>= 0)
    real t;        // the ray's length to the point
    int object;    // the object met
    bool front;    // whether the ray met its front (flipped where antimatter shows its inside)
    bool planar;   // flat to m_normal() (a face or a ring): a source's size widens a rough lobe
};

// gaussamp(): SPECULAR rays drawn from the Gaussian of roughness^2 alpha2, reflected (their
// half vectors about the normal, leaving above the surface) or transmitted (the ray's direction
// offset in the tangent plane, leaving behind it); one ray (up to 10 tries) or, with -ss above
// 1.5, -ss x weight rays sharing the coefficient. (RADIANCE reweights reflected samples' values
// afterwards; rcontrib's contributions, taken as the rays arrive, keep the plain share, and so do
// ours.) normal faces the ray.
void PushGaussianSamples(IN(Ray) r, real3 colour, real alpha2, real3 point, real3 normal,
                         bool transmit) {
    Ray c;
    if (!Spawn(r, kSpecular, colour, c)) return;
    int target = 1;
    if (params.ss > 1.5) {
        target = int(params.ss * r.weight + .5);
        if (c.weight <= params.lw * real(target)) target = int(c.weight / params.lw);
        if (target > 1) {
            c.coef /= real(target);
            c.weight /= real(target);
        } else {
            target = 1;
        }
    }
    real3 u, v;
    Tangents(normal, u, v);
    int taken = 0;
    DONT_UNROLL for (int trial = 0; taken < target && trial < 10 * target; ++trial) {
        real phi = 2. * kPi * Rand();
        real rv1 = Rand();
        if (params.ss >= 0. && params.ss < 1.) rv1 = 1. - params.ss * rv1;
        real d = rv1 <= kTiny ? 1. : sqrt(alpha2 * -log(rv1));
        real3 offset = d * (cos(phi) * u + sin(phi) * v);
        real3 dir;
        if (transmit) {
            dir = r.dir + offset;
            if (dot(dir, normal) >= -kTiny) continue;
        } else {
            real3 h = normal + offset;
            dir = r.dir + (-2. * dot(h, r.dir) / (1. + d * d)) * h;
            if (dot(dir, normal) <= kTiny) continue;
        }
        c.org = point;
        c.dir = normalize(dir);
        PushTrace(c);
        ++taken;
    }
}

#ifdef DAYFLUX_DIELECTRIC
// m_dielectric(): Fresnel reflection and refraction at an interface of index n (+ the Hartmann
// constant / 500 nm); the refracted ray carries the solid angle ratio. Inside, the colour is a
// transmission per unit length, an extinction that RADIANCE's raycontrib() leaves out of
// contributions (with a warning, the packer's): only rayorigin()'s weights see it.
void ShadeDielectric(IN(Ray) r, IN(PackedSurface) m, IN(ShadingPoint) sp) {
    real3 point = sp.point, normal = sp.normal;
    real cos1 = sp.rod;
    PackedSurface unit = m;  // the pattern alone
    unit.color = vec4(1, 1, 1, m.color.w);
    real3 pcol = Colour(unit, r, point, normal, sp.t), ext;
    for (int k = 0; k < 3; ++k) {  // RADIANCE's mylog()
        real x = real(m.color[k]) * pcol[k];
        ext[k] = x < 1e-38 ? 100.0 : x >= 1.0 ? 0.0 : -log(x);
    }
    real nratio = m.color.w;
    Ray inc = r;  // the incident ray: inside, it travelled in the medium
    inc.t = sp.t;
    real3 ctrans = real3(0);
    if (!sp.front) {
        inc.cext = ext;
    } else {
        nratio = 1.0 / nratio;
        ctrans = ext;
    }
    real refl = 1.0;
    real d2 = 1.0 - nratio * nratio * (1.0 - cos1 * cos1);
    if (d2 >= kTiny) {  // else total reflection
        real cos2 = sqrt(d2);
        real a = (cos1 - nratio * cos2) / (cos1 + nratio * cos2);
        real b = (1.0 / cos1 - nratio / cos2) / (1.0 / cos1 + nratio / cos2);
        refl = .5 * (a * a + b * b);
        Ray c;
        if (Spawn(inc, kRefracted, real3((1.0 - refl) * nratio * nratio), c)) {
            c.org = point;
            c.dir = normalize(nratio * r.dir + (nratio * cos1 - cos2) * normal);
            c.cext = ctrans;
            PushTrace(c);
        }
    }
    if ((r.crtype & kShadow) != 0) return;
    PushChild(inc, kReflected, real3(refl), point, normalize(r.dir + 2.0 * cos1 * normal));
}
#endif

#ifdef DAYFLUX_BSDF
// m_bsdf() for MAT_BSDF and MAT_ABSDF with Klems data: the non-diffuse parts of reflection and
// transmission sampled from the matrices (or, below -st, folded into the diffuse part), the
// diffuse parts as ambient hemispheres on either side, and the sources through the BSDF itself.
// A thickness makes the surface a proxy: rays other than scattered ones pass, and transmitted
// rays leave from that far behind it. An aBSDF's peak about the straight-through direction
// (ComputeThrough) passes shadow rays, and the rays that are neither specular nor ambient, as
// one unscattered ray, whose direction its samples then leave out.
void ShadeBsdf(IN(Ray) r, IN(PackedSurface) m, IN(ShadingPoint) sp) {
    real3 point = sp.point, normal = sp.normal;
    real t = sp.t;
    int b = m.fore;
    bool front = sp.front;
    real3 front_normal = front ? normal : -normal;  // the BSDF's frame: the surface's own side
    real thick = BsdfThickness(b, r, point, front_normal, t);
    if (abs(thick) <= kTiny) thick = 0.;
    if (thick != 0. && ((r.crtype & kShadow) != 0 || (r.crtype & (kSpecular | kAmbient)) == 0 ||
                        (thick > 0.) != front)) {
        PushChild(r, kTrans, real3(1), point, r.dir);  // hide the proxy
        return;
    }
    bool aperture = (int(m.params.w) & kSurfaceAperture) != 0;
    if ((r.crtype & kShadow) != 0 && !aperture) return;
    real3 pcol = Colour(m, r, point, front_normal, t);  // colour 1: the pattern alone
    int e = front ? kKlemsFrontReflection : kKlemsBackReflection;
    real3 rdiff = (KlemsLambertian(b, false, front) +
                   real3(klems[b + e], klems[b + e + 1], klems[b + e + 2])) *
                  pcol;
    real3 tdiff = (KlemsLambertian(b, true, front) + real3(klems[b + kKlemsTransmission],
                                                           klems[b + kKlemsTransmission + 1],
                                                           klems[b + kKlemsTransmission + 2])) *
                  pcol;
    real3 up = BsdfUp(b, r, point, front_normal, t);
    BsdfFrame frame;
    if (!MakeBsdfFrame(up, front_normal, r.dir, frame)) {
        reports |= kReportBsdfFrame;
        return;
    }
    real through = 0., surround = 0.;  // (nought in scenes without aBSDF)
#ifdef DAYFLUX_APERTURE
    if (aperture) ComputeThrough(b, frame.view, front, Bright(pcol) > kTiny, through, surround);
#endif
    real3 thru = through * pcol;  // the peak's coefficient
    bool has_thru = Bright(thru) > kTiny;
    if ((r.crtype & kShadow) != 0) {
        if (through > 0.) PushChild(r, kTrans, thru, point, r.dir);
        return;
    }
    real3 kview = frame.view;
    // the BSDF's resolution about the view: sqrt of the smallest and largest projected solid
    // angles
    real2 ksr = sqrt(SizeMinMax(b, kview));
    real3 behind = point - thick * front_normal;
    // sample_sdf() for reflection, then transmission: a specular ray from the part serving the
    // ray's side, or (below -st) the total left to the ambient hemisphere on that side.
    DONT_UNROLL for (int xmit = 0; xmit < 2; ++xmit) {
        real3 unsampled = real3(0);
        int q = xmit == 1 ? PartT(b, kview.z > 0.) : PartR(b, kview.z > 0.);
        if (q >= 0) {
            // an aBSDF's peak, for rays neither specular nor ambient: one ray straight through
            // (the samples leave its direction out even where rayorigin() refused that ray, as
            // sample_sdcomp() does)
            bool view = xmit == 1 && (r.crtype & (kSpecular | kAmbient)) == 0 && has_thru;
            real viewed = view && PushChild(r, kTrans, thru, point, r.dir) ? Bright(thru) : 0.;
            real hemi = 0.;
            if (klems[q + kPartMaxHemi] - viewed > kTiny) {
                real u = Rand(), v = Rand();
                hemi = max(0., SpecularHemi(b, KJitter(kview, ksr.y, u, v), xmit == 1) - viewed);
            }
            if (hemi <= params.st + kTiny) {  // (no pattern on reflection)
                if (hemi > kTiny) unsampled = hemi * (xmit == 1 ? pcol : real3(1));
            } else {
                // -ss above 1.5: -ss x weight samples, stratified in xrand, sharing the value
                int target = params.ss > 1.5 ? max(1, int(params.ss * r.weight + .5)) : 1;
                DONT_UNROLL for (int n = 0; n < target; ++n) {
                    real xrand = Rand();
                    if (target == 1) {
                        if (params.ss < 1.) xrand = .5 + params.ss * (xrand - .5);
                    } else {
                        xrand = (real(n) + xrand) / real(target);
                    }
                    real u = Rand(), v = Rand();
                    real3 vsmp = KJitter(kview, ksr.x, u, v), outv;
                    real pu = Rand(), pv = Rand();
                    real value = KlemsSample(q, vsmp, xrand, pu, pv, outv);
                    if (value <= kTiny) break;
                    if (view) {  // the peak's direction: the straight ray carries it
                        real dx = vsmp.x + outv.x, dy = vsmp.y + outv.y;
                        if (dx * dx + dy * dy <= ksr.x * ksr.x) continue;
                    }
                    if (target > 1) value /= real(target);
                    Ray c;
                    if (!Spawn(r, kSpecular, value * (xmit == 1 ? pcol : real3(1)), c)) {
                        if (n == 0 && target > 1) {  // RADIANCE lowers its target, starts again
                            int before = target;
                            target = int(real(target) * c.weight / params.lw);
                            if (target == before) break;
                            n = -1;
                        }
                        continue;
                    }
                    c.org = xmit == 1 ? behind : point;
                    c.dir = ToWorld(frame, outv);
                    PushTrace(c);
                }
            }
        }
        // The diffuse part and what was not sampled, as an ambient hemisphere on that side
        // (m_bsdf() moves a proxy's origin along the normal as flipped for a front hit only).
        real3 origin = xmit == 0 ? point : point + thick * (front ? -front_normal : front_normal);
        PushHemisphere(r, (xmit == 0 ? rdiff : tdiff) + unsampled, origin,
                       xmit == 0 ? normal : -normal);
    }
    if (params.ndirect == 0) return;
    // direct(): dir_bsdf(), or dir_brdf() and dir_btdf() apart for a proxy.
    BsdfDirect direct;
    direct.bsdf = b;
    direct.up = up;
    direct.rdiff = rdiff;
    direct.tdiff = tdiff;
    direct.pattern = pcol;
    direct.surround = surround;
    Item it;
    it.r = r;
    it.kind = kItemDirectBsdf;
    it.normal = normal;
    it.next = 0;
    it.end = params.nsources;
    it.part = 0;
    it.turn = Pcg(rng ^ 0x68e31da4u);
    bool reflect_only = Bright(tdiff) <= kTiny && !HasTransmission(b);
    int side = front ? kBsdfFront : 0;
    it.point = point;
    direct.sides = side | kBsdfReflect | (reflect_only || thick != 0. ? 0 : kBsdfTransmit) |
                   (has_thru ? kBsdfThrough : 0);
    PutBsdfDirect(it, direct);
    PushItem(it);
    if (thick != 0. && !reflect_only) {
        it.point = behind;
        direct.sides = side | kBsdfTransmit;
        PutBsdfDirect(it, direct);
        PushItem(it);
    }
}
#endif

// m_mirror() toward a source's image: a shadow ray aimed at the image that meets its mirror
// goes on toward the source imaged, whatever the limits (rayorigin()'s verdict is ignored).
void RelayShadowRay(IN(Ray) r, real3 colour, real3 point, real3 reflected) {
    Ray c;
    ChildRay(r, kReflected, colour, c);
    c.aimed = sources[r.aimed].next;
    c.org = point;
    c.dir = reflected;
    PushTrace(c);
}

// plastic, metal, trans, glass, mirror, dielectric, BSDF: one material's own scattering.
void ShadeBasic(IN(Ray) r, IN(PackedSurface) m, IN(ShadingPoint) sp) {
    if (m.kind == kMatBlack || m.kind == kMatGlow || m.kind == kMatLight || m.kind == kMatIllum ||
        m.kind == kMatAntimatter)  // (a mixfunc's side: not RADIANCE's use of it)
        return;
#ifdef DAYFLUX_BSDF
    if (m.kind == kMatBsdf) {
        ShadeBsdf(r, m, sp);
        return;
    }
#endif
#ifdef DAYFLUX_DIELECTRIC
    if (m.kind == kMatDielectric) {
        ShadeDielectric(r, m, sp);
        return;
    }
#endif
    real3 point = sp.point, normal = sp.normal;
    real rod = sp.rod;
    real3 c = Colour(m, r, point, normal, sp.t);
    if (m.kind == kMatMirror) {  // its back is black
        if (!sp.front) return;
        real3 reflected = normalize(r.dir + 2. * rod * normal);
#ifdef DAYFLUX_MIRROR_IMAGES
        // Shade() set r.from to the object met.
        if (r.aimed >= 0 && sources[r.aimed].relay >= 0 && sources[r.aimed].object == r.from) {
            RelayShadowRay(r, c, point, reflected);
            return;
        }
#endif
        if ((r.crtype & kShadow) != 0) return;  // shadow rays aimed at other sources stop here
        PushChild(r, kReflected, c, point, reflected);
        return;
    }
    if (m.kind == kMatGlass) {
        real3 mc = max(c, real3(1e-15));
        bool hastrans = Max3(c) > 1e-15;
        real n = m.color.w, pdot = rod;
        real cos2 = sqrt((1.0 - 1.0 / (n * n)) + pdot * pdot / (n * n));
        if (hastrans) mc = pow(mc, real3(1.0 / cos2));
        real r1e = (pdot - n * cos2) / (pdot + n * cos2);
        r1e *= r1e;
        real r1m = (1.0 / pdot - n / cos2) / (1.0 / pdot + n / cos2);
        r1m *= r1m;
        if (hastrans) {
            real3 tr = .5 * (1.0 - r1e) * (1.0 - r1e) * mc / (1.0 - r1e * r1e * mc * mc) +
                       .5 * (1.0 - r1m) * (1.0 - r1m) * mc / (1.0 - r1m * r1m * mc * mc);
            PushChild(r, kTrans, tr, point, r.dir);
        }
        if ((r.crtype & kShadow) != 0) return;  // shadow rays only pass through
        real3 dd = mc * mc;
        real3 refl = .5 * r1e * (1.0 + (1.0 - 2.0 * r1e) * dd) / (1.0 - r1e * r1e * dd) +
                     .5 * r1m * (1.0 + (1.0 - 2.0 * r1m) * dd) / (1.0 - r1m * r1m * dd);
        PushChild(r, kReflected, refl, point, normalize(r.dir + 2. * pdot * normal));
        return;
    }
    // plastic, metal, trans (m_normal()): pure specular reflection with RADIANCE's Fresnel
    // estimate raising the specularity at grazing angles, or rough (Gaussian) reflection sampled
    // or, below -st, folded into the diffuse part; diffuse transmission, and specular
    // transmission pure (shadow rays pass) or rough: sampled, or below -st folded into the
    // hemisphere behind, which m_normal() traces only where some transmission is diffuse.
    real spec = m.params.x;
    bool metal = (int(m.params.w) & kSurfaceMetal) != 0;
    bool pure = m.alpha2 <= kTiny;
    real rspec = spec, fest = 0.;
    real pdot = max(rod, .001);
    if (pure && rspec >= kFresnelThreshold) {
        fest = FresnelEstimate(pdot);
        rspec += fest * (1. - rspec);
    }
    real trans = real(m.params.y) * (1. - rspec), tspec = trans * real(m.params.z);
    real tdiff = trans - tspec;
    bool rough_trans = !pure && tspec > kTiny;
    bool rough_trans_below_threshold = rough_trans && params.st >= tspec - kTiny;
    if (pure && tspec > kTiny) PushChild(r, kTrans, c * tspec, point, r.dir);  // shadow rays too
    if ((r.crtype & kShadow) != 0) return;  // the rest blocks shadow rays
    real3 sc = real3(0);
    bool rough_below_threshold = false, sample_reflection = false;
    if (rspec > kTiny) {
        sc = real3(rspec);
        if (metal) sc = fest > kTiny ? fest + c * spec * (1. - fest) : c * rspec;
        if (pure)
            PushChild(r, kReflected, sc, point, normalize(r.dir + 2. * pdot * normal));
        else if (params.st >= rspec - kTiny)
            rough_below_threshold = true;
        else
            sample_reflection = true;
    }
    // gaussamp(): the transmitted samples, then the reflected ones, from one call (the GPU's
    // compiler inlines a function at every call)
    DONT_UNROLL for (int lobe = 0; lobe < 2; ++lobe) {
        bool transmit = lobe == 0;
        if (transmit ? rough_trans && !rough_trans_below_threshold : sample_reflection)
            PushGaussianSamples(r, transmit ? c * tspec : sc, m.alpha2, point, normal, transmit);
    }
    real rdiff = 1.0 - trans - rspec;
    if (pure && rdiff <= kTiny && tdiff <= kTiny) return;
    PushDirect(r, c, rdiff, tdiff, trans,
               (pure && spec >= kFresnelThreshold ? kDirectFresnel : 0) |
                   (rough_trans ? kDirectRoughTransmission : 0) | (sp.planar ? kDirectFlat : 0),
               point, normal, sc, pure ? 0.0 : real(m.alpha2));
    // the hemisphere behind, then the one in front, from one call (as above)
    DONT_UNROLL for (int side = 0; side < 2; ++side) {
        bool behind = side == 0;
        if (behind ? tdiff > kTiny : rdiff > kTiny)
            PushHemisphere(r,
                           behind ? c * (rough_trans_below_threshold ? trans : tdiff)
                                  : c * rdiff + (rough_below_threshold ? sc : real3(0)),
                           point, behind ? -normal : normal);
    }
}

// m_clip(): entering antimatter adds its modifiers to the clip set of the rays passed on,
// leaving removes them. Where it names a material for its inside and the ray went into what is
// cut, the ray meets the cut's side: returns that material's surface, to be shaded as seen
// from the other side of this one (flipsurface()); else passes the ray on and returns -1.
int PassAntimatter(INOUT(Ray) r, IN(PackedSurface) m, INOUT(ShadingPoint) sp) {
    uint bits = AntimatterClips(m);
    r.next_clip = sp.front ? r.clip | bits : r.clip & ~bits;
#ifdef DAYFLUX_INSIDE
    if (AntimatterInside(m) >= 0) {
        int inside = 0;
        uint counters = AntimatterCounters(m);
        for (int c = 0; c < 16; ++c)
            if (((counters >> uint(c)) & 1u) != 0u) inside += InsideCount(r.inside, c);
        if (inside > 0) {
            sp.front = !sp.front;
            return AntimatterInside(m);
        }
    }
#endif
    PushChild(r, kTrans, real3(1), sp.point, r.dir);
    return -1;
}

// What a material does with a ray (after Shade's rules for lights, antimatter and -i). A mirror
// with a substitute material: m_mirror() gives it the rays other than those the direct
// calculation sends through the mirror toward an image, and ambient and specular rays meeting
// its front (the light those would find comes through the images). A mixfunc, raymixture():
// each side shades its share of the ray (a void side lets its share through). GLSL has no
// recursion, so the sides of mixfuncs of mixfuncs wait on a small stack (MIX_STACK: the host
// refuses trees deeper than it holds). One call of ShadeBasic, so that the GPU's compiler
// inlines it once.
void ShadeMaterial(INOUT(Ray) r, INOUT(PackedSurface) m, INOUT(ShadingPoint) sp) {
    bool substituted =
        !(r.aimed >= 0 && sources[r.aimed].relay >= 0 && sources[r.aimed].object == sp.object) &&
        !((r.crtype & (kAmbient | kSpecular)) != 0 && sp.front);
    int waiting[MIX_STACK];
    real waiting_share[MIX_STACK];
    int nwaiting = 0;
    real share = 1.;
    // Each side shades the ray's share: r scaled, then restored for the next.
    real weight = r.weight;
    real3 coef = r.coef;
    uint next_clip = r.next_clip;
    for (;;) {
        r.weight = weight * share;
        r.coef = coef * share;
        r.next_clip = next_clip;
        if (m.kind == kMatMirror && (int(m.params.w) & kSurfaceMirrorAlternate) != 0 &&
            substituted) {
            if (m.fore < 0) {
                PushChild(r, kTrans, real3(1), sp.point, r.dir);
            } else {
                m = surfaces[m.fore];
                if (m.kind != kMatAntimatter) continue;  // shaded as the mirror would have been
                int inside = PassAntimatter(r, m, sp);
                if (inside >= 0) {
                    next_clip = r.next_clip;
                    m = surfaces[inside];
                    continue;
                }
            }
        } else if (m.kind == kMatMix) {
            SetRayVariables(r, sp.point, sp.normal, sp.t);
            real c = clamp(real(PatternRGB(m.pattern).x), 0.0, 1.0);
            for (int side = 1; side >= 0; --side) {  // the foreground is shaded first
                real fraction = side == 0 ? c : 1. - c;
                if (fraction <= kTiny) continue;
                int s = side == 0 ? m.fore : m.back;
                if (s < 0) {
                    r.weight = weight * share * fraction;
                    r.coef = coef * share * fraction;
                    PushChild(r, kTrans, real3(1), sp.point, r.dir);
                    continue;
                }
                waiting[nwaiting] = s;
                waiting_share[nwaiting] = share * fraction;
                ++nwaiting;
            }
        } else {
            ShadeBasic(r, m, sp);
        }
        if (nwaiting == 0) return;
        --nwaiting;
        m = surfaces[waiting[nwaiting]];
        share = waiting_share[nwaiting];
    }
}

// The shading point of a ray that met h: a surface, or a distant source (never planar).
ShadingPoint ShadingPointOf(IN(Ray) r, IN(Hit) h) {
    ShadingPoint sp;
    real rod = -dot(r.dir, h.normal);
    sp.point = h.point;
    sp.normal = rod < 0. ? -h.normal : h.normal;
    sp.rod = abs(rod);
    sp.t = h.t;
    sp.object = h.object;
    sp.front = rod > 0.;
    sp.planar = h.planar;
    return sp;
}

// A ray reaches what h holds: a surface (material h.m, counting for tracked modifier h.tracked)
// or, escaping, a distant source (h.source >= 0): its contribution where that is tracked, then
// m_light()'s rules, antimatter, -i, and the material, at its shading point (ShadingPointOf).
void Shade(INOUT(Ray) r, INOUT(Hit) h) {
    ShadingPoint sp = ShadingPointOf(r, h);
    int k = h.tracked, source = h.source;
    r.from = sp.object;  // the rays it spawns leave this object
    // A ray aimed at a source counts only there (trace_contrib()).
    bool aimed_elsewhere = r.aimed >= 0 && sp.object != sources[r.aimed].object;
    if (aimed_elsewhere) k = -1;
    bool light = h.m.kind == kMatLight || h.m.kind == kMatIllum;
    if (light) {
        // m_light(): an ambient or specular ray reaching a light from the front counts nothing
        // (direct() samples it); so does a shadow ray aimed at another source, unless this is
        // an illum it may pass (not in front of an illum or glow it aims at); direct() sends no
        // shadow ray toward a sample it would reach from behind (open tube ends). An illum that
        // a ray was not aimed at passes it on to its alternate material.
        bool shadow = (r.crtype & kShadow) != 0;
        if ((r.crtype & (kAmbient | kSpecular)) != 0 && !shadow && sp.front) return;
        if (aimed_elsewhere &&
            (h.m.kind != kMatIllum || (sp.front && (int(sources[r.aimed].v.w) & kSourceWeak) != 0)))
            return;
        if (shadow && r.aimed >= 0 && !aimed_elsewhere && !sp.front) return;
        bool pass = h.m.kind == kMatIllum && (r.aimed < 0 || aimed_elsewhere);
        if (k >= 0) {
            bool lit = !pass && sp.front &&
                       !(h.m.alpha2 > 0. &&
                         real(h.m.alpha2) < 2. * kPi * (1. + dot(XYZ(h.m.params), r.dir)));
            Contribute(k, r, sp.point, sp.normal, sp.t, source,
                       params.contributions == 0 ? real3(1)
                       : lit                     ? Colour(h.m, r, sp.point, sp.normal, sp.t)
                                                 : real3(0));
        }
        // A distant source passes a ray on to nothing: it lies at infinity (RADIANCE traces on
        // from there, meeting it again until -lr; a ray from 1e30 is none of Embree's).
        if (!pass || source >= 0) return;
        if (h.m.fore < 0) {
            PushChild(r, kTrans, real3(1), sp.point, r.dir);
            return;
        }
        h.m = surfaces[h.m.fore];  // rayshade() with the alternate material
        // (which -i leaves as it is where it is a light too, as rayshade() does: its params
        // hold no surface flags)
        light = h.m.kind == kMatLight || h.m.kind == kMatIllum;
    } else if (k >= 0) {
#ifdef DAYFLUX_ASUB
        if (r.mis > 0. && (int(h.m.params.w) & kSurfaceSampled) != 0) {
            // a hemisphere ray meeting a receiver its surface sampled too: its share
            Ray met = r;
            met.coef *= HemisphereShare(r, sp.t, sp.rod);
            Contribute(
                k, met, sp.point, sp.normal, sp.t, source,
                params.contributions != 0 ? Colour(h.m, r, sp.point, sp.normal, sp.t) : real3(1));
        } else
#endif
            Contribute(
                k, r, sp.point, sp.normal, sp.t, source,
                params.contributions != 0 ? Colour(h.m, r, sp.point, sp.normal, sp.t) : real3(1));
    }
    if (h.m.kind == kMatAntimatter) {
        int inside = PassAntimatter(r, h.m, sp);
        if (inside < 0) return;
        h.m = surfaces[inside];
    }
    // -i: primary rays (and rays straight through transparent things before them) find the
    // first opaque surface and measure irradiance there, as off a Lambertian surface of
    // reflectance pi (RADIANCE's raytirrad()); light sources stay what they are.
    if (params.first_hit != 0 && (r.crtype & ~(kPrimary | kTrans)) == 0 && !light &&
        h.m.kind != kMatGlow) {
        if ((int(h.m.params.w) & kSurfaceTransparent) != 0) {
            PushChild(r, kTrans, real3(1), sp.point, r.dir);
            return;
        }
        h.m.kind = kMatDiffuse;
        h.m.color = vec4(kPi, kPi, kPi, 0);
        h.m.params = vec4(0);
        h.m.alpha2 = 0.;
        h.m.pattern = -1;
    }
    ShadeMaterial(r, h.m, sp);
}
