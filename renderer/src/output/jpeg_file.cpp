// SPDX-License-Identifier: MIT
// JPEG through libjpeg(-turbo) directly rather than the OpenImageIO plug-in: loading OpenImageIO
// alone took about 0.17 s, most of a 640x480 JPEG's 0.4-0.9 s write, and its libjpeg error
// handler printed libjpeg's own message (a full disk left the temporary file and no
// `whitted: error:` line). Here errors come back as exceptions and the caller removes the file.

#include "output/jpeg_file.h"

#include "output/format_plugins.h"

#include <jpeglib.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace whitted {
namespace {

struct ErrorManager {
    jpeg_error_mgr base;  // first: libjpeg hands back a pointer to it
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

extern "C" void on_jpeg_error(j_common_ptr info) {
    auto* errors = reinterpret_cast<ErrorManager*>(info->err);
    errors->base.format_message(info, errors->message);
    std::longjmp(errors->jump, 1);
}

extern "C" void on_jpeg_message(j_common_ptr, int) {}  // warnings: nothing a user could act on

/// Everything libjpeg needs, prepared before it runs: its errors longjmp, which must not jump
/// over C++ objects with destructors.
struct JpegJob {
    std::FILE* file;
    int width, height;
    const unsigned char* rows;
    const unsigned char* exif;
    unsigned exif_size;
    const char* comment;
    unsigned comment_size;
    const unsigned char* icc;
    unsigned icc_size;
};

bool run(const JpegJob& job, ErrorManager& errors) {
    jpeg_compress_struct info{};
    info.err = jpeg_std_error(&errors.base);
    errors.base.error_exit = on_jpeg_error;
    errors.base.emit_message = on_jpeg_message;
    if (setjmp(errors.jump)) {
        jpeg_destroy_compress(&info);
        return false;
    }
    jpeg_create_compress(&info);
    jpeg_stdio_dest(&info, job.file);
    info.image_width = JDIMENSION(job.width);
    info.image_height = JDIMENSION(job.height);
    info.input_components = 3;
    info.in_color_space = JCS_RGB;
    jpeg_set_defaults(&info);
    jpeg_set_quality(&info, 98, TRUE);  // OpenImageIO's default, which Whitted's JPEGs had before
    jpeg_start_compress(&info, TRUE);
    if (job.exif_size) jpeg_write_marker(&info, JPEG_APP0 + 1, job.exif, job.exif_size);
    if (job.icc_size) jpeg_write_icc_profile(&info, job.icc, job.icc_size);
    if (job.comment_size)
        jpeg_write_marker(&info, JPEG_COM, reinterpret_cast<const JOCTET*>(job.comment), job.comment_size);
    while (info.next_scanline < info.image_height) {
        auto* row = const_cast<JSAMPROW>(job.rows + size_t(info.next_scanline) * size_t(job.width) * 3);
        jpeg_write_scanlines(&info, &row, 1);
    }
    jpeg_finish_compress(&info);
    jpeg_destroy_compress(&info);
    return true;
}

/// An Exif APP1 block with IFD0's ImageDescription and Software (big-endian TIFF structure),
/// where OpenImageIO, ExifTool and PIL look for them.
std::vector<unsigned char> exif_block(const std::string& description, const std::string& software) {
    std::vector<unsigned char> b = {'E', 'x', 'i', 'f', 0, 0, 'M', 'M', 0, 42, 0, 0, 0, 8};
    const auto u16 = [&](uint32_t v) {
        b.push_back(static_cast<unsigned char>(v >> 8));
        b.push_back(static_cast<unsigned char>(v));
    };
    const auto u32 = [&](uint32_t v) {
        u16(v >> 16);
        u16(v & 0xFFFF);
    };
    const std::string strings[2] = {description, software};
    // Offsets count from the TIFF header ("MM"), 6 bytes into the block.
    uint32_t data = 8 + 2 + 2 * 12 + 4;
    u16(2);
    const uint16_t tags[2] = {0x010E, 0x0131};
    for (int i = 0; i < 2; ++i) {
        const auto count = uint32_t(strings[i].size() + 1);
        u16(tags[i]);
        u16(2);  // ASCII
        u32(count);
        u32(data);  // each is longer than 4 bytes, so stored apart
        data += count;
    }
    u32(0);  // no next IFD
    for (const std::string& s : strings) {
        b.insert(b.end(), s.begin(), s.end());
        b.push_back(0);
    }
    return b;
}

}  // namespace

void write_jpeg(const std::string& path, int width, int height, const float* rgb,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                const std::vector<unsigned char>& icc_profile) {
    std::vector<unsigned char> rows(size_t(width) * size_t(height) * 3);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 65536), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const float v = rgb[i] > 0 ? std::min(rgb[i], 1.0f) : 0.0f;  // NaN fails `> 0`
            rows[i] = static_cast<unsigned char>(double(v) * 255.0 + 0.5);
        }
    });
    std::string comment, software;
    for (const auto& [key, value] : metadata) {
        if (key == "Software")
            software = value;
        else
            comment += key + ": " + value + "\n";
    }
    // A marker holds at most 65533 bytes; the metadata is a few hundred.
    if (comment.size() > 65000) comment.resize(65000);
    std::vector<unsigned char> exif = exif_block(comment, software);
    if (exif.size() > 65533) exif.clear();

    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot open '" + path + "' for writing: " + std::strerror(errno));
    ErrorManager errors{};
    const JpegJob job{file,
                      width,
                      height,
                      rows.data(),
                      exif.data(),
                      unsigned(exif.size()),
                      comment.c_str(),
                      unsigned(comment.size()),
                      icc_profile.data(),
                      unsigned(icc_profile.size())};
    errno = 0;
    const bool wrote = run(job, errors);
    const int write_errno = errno;
    const bool closed = std::fclose(file) == 0;
    if (!wrote)
        throw std::runtime_error(std::string("libjpeg: ") + errors.message +
                                 (write_errno ? std::string(" (") + std::strerror(write_errno) + ")" : ""));
    if (!closed) throw std::runtime_error("cannot finish '" + path + "': " + std::strerror(errno));
}

}  // namespace whitted

extern "C" WHITTED_PLUGIN_EXPORT void whitted_write_jpeg(const std::string& path, int width, int height,
                                                         const float* rgb, const whitted::ImageMetadata& metadata,
                                                         const std::vector<unsigned char>& icc_profile) {
    whitted::write_jpeg(path, width, height, rgb, metadata, icc_profile);
}
