// SPDX-License-Identifier: MIT
// The profile is built rather than shipped: four displays times two primaries and curves would
// be files to keep in step with the OCIO config, and a matrix/TRC profile is a few hundred
// bytes of arithmetic (ICC.1:2010, ICC v4.3).

#include "output/icc_profile.h"

#include "output/chromaticities.h"

#include <cmath>
#include <cstdint>

namespace whitted {
namespace {

class Writer {
public:
    void u32(uint32_t v) {
        for (const int shift : {24, 16, 8, 0}) bytes.push_back(static_cast<unsigned char>(v >> shift));
    }
    void u16(uint16_t v) {
        bytes.push_back(static_cast<unsigned char>(v >> 8));
        bytes.push_back(static_cast<unsigned char>(v & 0xFF));
    }
    void sig(const char (&s)[5]) { bytes.insert(bytes.end(), s, s + 4); }
    /// s15Fixed16Number
    void fixed(double v) { u32(static_cast<uint32_t>(static_cast<int32_t>(std::lround(v * 65536.0)))); }
    void align() {
        while (bytes.size() % 4) bytes.push_back(0);
    }
    std::vector<unsigned char> bytes;
};

std::vector<unsigned char> mluc(const std::string& ascii) {
    Writer w;
    w.sig("mluc");
    w.u32(0);
    w.u32(1);   // one record
    w.u32(12);  // record size
    w.sig("enUS");
    w.u32(uint32_t(2 * ascii.size()));
    w.u32(28);  // the string's offset from the tag's start
    for (const char c : ascii) w.u16(static_cast<unsigned char>(c) < 0x80 ? uint16_t(c) : uint16_t('?'));
    return w.bytes;
}

std::vector<unsigned char> xyz(const std::array<double, 3>& v) {
    Writer w;
    w.sig("XYZ ");
    w.u32(0);
    for (const double c : v) w.fixed(c);
    return w.bytes;
}

std::vector<unsigned char> sf32(const Matrix3& m) {
    Writer w;
    w.sig("sf32");
    w.u32(0);
    for (const auto& row : m)
        for (const double c : row) w.fixed(c);
    return w.bytes;
}

/// A parametric curve (code → linear): type 0 is y = x^g, type 3 the sRGB piecewise curve.
std::vector<unsigned char> para(DisplayEncoding::Transfer transfer) {
    Writer w;
    w.sig("para");
    w.u32(0);
    using T = DisplayEncoding::Transfer;
    if (transfer == T::srgb) {
        w.u16(3);
        w.u16(0);
        for (const double p : {2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045}) w.fixed(p);
    } else {
        w.u16(0);
        w.u16(0);
        w.fixed(transfer == T::gamma22 ? 2.2 : transfer == T::gamma24 ? 2.4 : 1.0);
    }
    return w.bytes;
}

}  // namespace

std::vector<unsigned char> icc_profile(const DisplayEncoding& encoding, const std::string& description) {
    if (!encoding.known()) return {};
    const Chromaticities& primaries = encoding.primaries == DisplayEncoding::Primaries::display_p3
                                          ? display_p3_chromaticities
                                          : rec709_chromaticities;
    // The profile connection space is D50: the D65 primaries are adapted to it (Bradford), and
    // the matrix that did it goes in 'chad' so a reader can undo it.
    const std::array<double, 3> d50{0.9642, 1.0, 0.8249};
    const std::array<double, 3> d65{primaries.white[0] / primaries.white[1], 1.0,
                                    (1 - primaries.white[0] - primaries.white[1]) / primaries.white[1]};
    const Matrix3 chad = bradford(d65, d50);
    const Matrix3 to_pcs = multiply(chad, rgb_to_xyz(primaries));
    const auto column = [&](size_t c) { return std::array<double, 3>{to_pcs[0][c], to_pcs[1][c], to_pcs[2][c]}; };

    const std::vector<unsigned char> curve = para(encoding.transfer);
    struct Tag {
        const char* signature;
        std::vector<unsigned char> data;
    };
    const std::vector<Tag> tags = {{"desc", mluc(description)},
                                   {"cprt", mluc("No copyright, use freely")},
                                   {"wtpt", xyz(d50)},
                                   {"chad", sf32(chad)},
                                   {"rXYZ", xyz(column(0))},
                                   {"gXYZ", xyz(column(1))},
                                   {"bXYZ", xyz(column(2))},
                                   {"rTRC", curve},
                                   {"gTRC", curve},
                                   {"bTRC", curve}};

    Writer body;  // the tag data, each 4-byte aligned; the three curves are one copy
    std::vector<std::pair<uint32_t, uint32_t>> places;
    const uint32_t data_start = 128 + 4 + 12 * uint32_t(tags.size());
    for (const Tag& tag : tags) {
        if (tag.signature[1] == 'T' && tag.signature[0] != 'r') {
            places.push_back(places.back());
            continue;
        }
        body.align();
        places.emplace_back(data_start + uint32_t(body.bytes.size()), uint32_t(tag.data.size()));
        body.bytes.insert(body.bytes.end(), tag.data.begin(), tag.data.end());
    }
    body.align();

    Writer w;
    w.u32(data_start + uint32_t(body.bytes.size()));  // profile size
    w.u32(0);                                         // preferred CMM: none
    w.u32(0x04300000);                                // version 4.3
    w.sig("mntr");
    w.sig("RGB ");
    w.sig("XYZ ");
    for (const uint16_t v : {2026, 1, 1, 0, 0, 0}) w.u16(v);  // a fixed date: same input, same bytes
    w.sig("acsp");
    for (int i = 0; i < 5; ++i) w.u32(0);  // platform, flags, manufacturer, model, attributes (8 bytes)...
    w.u32(0);                              // ...attributes' second half
    w.u32(0);                              // rendering intent: perceptual
    for (const double c : d50) w.fixed(c);
    w.u32(0);                                  // creator
    for (int i = 0; i < 4 + 7; ++i) w.u32(0);  // profile ID (0: not computed) and reserved bytes
    w.u32(uint32_t(tags.size()));
    for (size_t i = 0; i < tags.size(); ++i) {
        w.bytes.insert(w.bytes.end(), tags[i].signature, tags[i].signature + 4);
        w.u32(places[i].first);
        w.u32(places[i].second);
    }
    w.bytes.insert(w.bytes.end(), body.bytes.begin(), body.bytes.end());
    return w.bytes;
}

}  // namespace whitted
