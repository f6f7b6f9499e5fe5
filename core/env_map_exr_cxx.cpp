// The C++ fallback of env_map_exr.c (see env_map_exr_cxx.h): OpenEXR's
// InputFile reads the first part of scanline and tiled files alike, from a
// stream over the same bytes the OpenEXRCore reader used.
#include "env_map_exr_cxx.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>

namespace {

// Imf::IStream over read_at: a file descriptor or a memory buffer.
class ReadAtStream : public OPENEXR_IMF_NAMESPACE::IStream {
  public:
    ReadAtStream(env_read_at_fn read_at, void *user, uint64_t size, const char *name)
        : IStream(name), read_at_(read_at), user_(user), size_(size), pos_(0)
    {
    }
    bool read(char c[], int n) override
    {
        if (n < 0 || pos_ + (uint64_t)n > size_)
            throw std::runtime_error("the file ends early (truncated)");
        int64_t got = read_at_(user_, c, (uint64_t)n, pos_);
        if (got != n)
            throw std::runtime_error("cannot read the file");
        pos_ += (uint64_t)n;
        return pos_ < size_;
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = pos; }

  private:
    env_read_at_fn read_at_;
    void *user_;
    uint64_t size_, pos_;
};

} // namespace

extern "C" int env_exr_decode_cxx(env_read_at_fn read_at, void *user, uint64_t file_size,
                                  const char *name, int grey, int width, int height,
                                  float *rgb, char *msg, size_t msg_size)
{
    namespace Imf = OPENEXR_IMF_NAMESPACE;
    try {
        ReadAtStream stream(read_at, user, file_size, name);
        Imf::InputFile file(stream, 1);
        const IMATH_NAMESPACE::Box2i &dw = file.header().dataWindow();
        if (dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height)
            throw std::runtime_error("the C++ library sees another data window");
        // Slices address pixel (x, y) of the data window at base + x*xs + y*ys.
        const size_t xs = 3 * sizeof(float), ys = xs * (size_t)width;
        char *origin = (char *)rgb - (ptrdiff_t)dw.min.x * (ptrdiff_t)xs -
                       (ptrdiff_t)dw.min.y * (ptrdiff_t)ys;
        Imf::FrameBuffer fb;
        static const char *const rgb_names[3] = {"R", "G", "B"};
        for (int c = 0; c < (grey ? 1 : 3); c++)
            fb.insert(grey ? "Y" : rgb_names[c],
                      Imf::Slice(Imf::FLOAT, origin + c * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(msg, msg_size, "%s", e.what());
    } catch (...) {
        std::snprintf(msg, msg_size, "unknown error in OpenEXR");
    }
    return -1;
}
