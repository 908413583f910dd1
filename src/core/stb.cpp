// The stb implementations, in a file of their own so the fuzz build can tell UBSan about them: stb_image
// 2.27 calls memcpy(NULL, src, 0) for an empty read from memory (harmless, undefined by the letter of the
// standard; found by fuzzing), see src/core/CMakeLists.txt.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb_image.h>
#include <stb_image_write.h>
