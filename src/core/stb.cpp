// The stb implementations, in a file of their own so the fuzz build can tell UBSan about them: stb_image
// 2.27 calls memcpy(NULL, src, 0) for an empty read from memory (harmless, undefined by the letter of the
// standard; found by fuzzing), see src/core/CMakeLists.txt.
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
// A 21-byte TGA header can ask for a 2048² image, which takes seconds to decode under the fuzz build's
// instrumentation: the fuzzers would spend their time there.
#define STBI_MAX_DIMENSIONS 128
#endif
// JPEG is libjpeg-turbo's (core/image.cpp): stb 2.27's Huffman table builder writes out of bounds.
// PNG is libpng's: stb 2.27 checks no CRC or zlib checksum, so damaged files decoded into wrong texels.
// stb keeps only TGA and BMP: its PNM reader overflows an int on long numbers (found by fuzzing), and
// GIF, PSD, PIC, PNM and HDR are no texture format a scene here names.
#define STBI_ONLY_TGA
#define STBI_ONLY_BMP
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb_image.h>
#include <stb_image_write.h>
