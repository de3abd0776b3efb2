#include "matrix/rgbe.h"

#include <cmath>

namespace dayflux {

namespace {
constexpr int kMinEncodedLength = 8;       // shorter scanlines are written flat
constexpr int kMaxEncodedLength = 0x7fff;  // as are longer ones
constexpr int kMinRun = 4;                 // shortest run worth encoding
constexpr int kExponentBias = 128;

bool ReadFlat(InputSource &in, Colr *scan, int len) {
    // Old-style lines, where (1,1,1,n) repeats the previous pixel n << shift times.
    int shift = 0;
    Colr *start = scan;
    while (len > 0) {
        uint8_t px[4];
        if (in.Read(px, 4) != 4) return false;
        if (px[0] == 1 && px[1] == 1 && px[2] == 1) {
            if (scan == start) return false;
            long count = static_cast<long>(px[3]) << shift;
            while (count-- > 0) {
                *scan = scan[-1];
                ++scan;
                if (--len <= 0) return true;
            }
            shift += 8;
        } else {
            *scan++ = Colr{px[0], px[1], px[2], px[3]};
            --len;
            shift = 0;
        }
    }
    return true;
}
}  // namespace

Colr ToColr(double r, double g, double b) {
    double d = std::max(r, g);
    if (b > d) d = b;
    if (d <= 1e-32) return Colr{0, 0, 0, 0};
    int e;
    d = std::frexp(d, &e) * 256.0 / d;
    Colr c;
    c[0] = r > 0 ? static_cast<uint8_t>(r * d) : 0;
    c[1] = g > 0 ? static_cast<uint8_t>(g * d) : 0;
    c[2] = b > 0 ? static_cast<uint8_t>(b * d) : 0;
    c[3] = static_cast<uint8_t>(e + kExponentBias);
    return c;
}

void FromColr(const Colr &c, float rgb[3]) {
    if (c[3] == 0) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    double f = std::ldexp(1.0, static_cast<int>(c[3]) - (kExponentBias + 8));
    rgb[0] = static_cast<float>((c[0] + 0.5) * f);
    rgb[1] = static_cast<float>((c[1] + 0.5) * f);
    rgb[2] = static_cast<float>((c[2] + 0.5) * f);
}

void EncodeScanline(const Colr *scan, int len, std::string *out) {
    if (len < kMinEncodedLength || len > kMaxEncodedLength) {
        out->append(reinterpret_cast<const char *>(scan), 4 * static_cast<size_t>(len));
        return;
    }
    out->push_back(2);
    out->push_back(2);
    out->push_back(static_cast<char>(len >> 8));
    out->push_back(static_cast<char>(len & 0xff));
    // Each component separately: runs of >= kMinRun equal bytes, literal stretches between.
    for (int i = 0; i < 4; ++i) {
        int cnt = 1;
        for (int j = 0; j < len; j += cnt) {
            int beg;
            for (beg = j; beg < len; beg += cnt) {
                for (cnt = 1; cnt < 127 && beg + cnt < len && scan[beg + cnt][i] == scan[beg][i];
                     ++cnt) {
                }
                if (cnt >= kMinRun) break;
            }
            if (beg - j > 1 && beg - j < kMinRun) {
                int c2 = j + 1;
                while (scan[c2++][i] == scan[j][i]) {
                    if (c2 == beg) {  // a short run
                        out->push_back(static_cast<char>(128 + beg - j));
                        out->push_back(static_cast<char>(scan[j][i]));
                        j = beg;
                        break;
                    }
                }
            }
            while (j < beg) {  // literal bytes
                int n = std::min(beg - j, 128);
                out->push_back(static_cast<char>(n));
                while (n--) out->push_back(static_cast<char>(scan[j++][i]));
            }
            if (cnt >= kMinRun) {
                out->push_back(static_cast<char>(128 + cnt));
                out->push_back(static_cast<char>(scan[beg][i]));
            } else {
                cnt = 0;
            }
        }
    }
}

bool DecodeScanline(InputSource &in, Colr *scan, int len) {
    if (len < kMinEncodedLength || len > kMaxEncodedLength) return ReadFlat(in, scan, len);
    int first = in.Peek();
    if (first < 0) return false;
    if (first != 2) return ReadFlat(in, scan, len);
    uint8_t head[4];
    if (in.Read(head, 4) != 4) return false;
    if (head[1] != 2 || (head[2] & 0x80)) {
        scan[0] = Colr{head[0], head[1], head[2], head[3]};
        return ReadFlat(in, scan + 1, len - 1);
    }
    if ((head[2] << 8 | head[3]) != len) return false;
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < len;) {
            int code = in.Get();
            if (code < 0) return false;
            if (code > 128) {
                code &= 127;
                int val = in.Get();
                if (val < 0 || j + code > len) return false;
                while (code--) scan[j++][i] = static_cast<uint8_t>(val);
            } else {
                if (j + code > len) return false;
                while (code--) {
                    int val = in.Get();
                    if (val < 0) return false;
                    scan[j++][i] = static_cast<uint8_t>(val);
                }
            }
        }
    }
    return true;
}

}  // namespace dayflux
