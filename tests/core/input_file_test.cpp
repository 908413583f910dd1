// Inputs that are not regular files are refused at once, naming the file; sizes are known before reading.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/input_file.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace rtr {
namespace {

struct InputFileTest : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_input_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
};

// Runs `fn` (which must throw rtr::Error) with a FIFO named `fifo` that nobody writes to. A reader that
// blocks in open() is released by opening the write end, and the test fails instead of hanging.
std::string errorOnFifo(const fs::path& fifo, const std::function<void()>& fn) {
  auto result = std::async(std::launch::async, [&]() -> std::string {
    try {
      fn();
      return "no error";
    } catch (const Error& e) { return e.what(); }
  });
  if (result.wait_for(std::chrono::seconds(5)) == std::future_status::timeout) {
    const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (w >= 0) ::close(w);
    result.wait();
    return "blocked on the FIFO";
  }
  return result.get();
}

TEST_F(InputFileTest, RefusesFifoDeviceAndFolderAtOnceNamingThem) {
  const fs::path fifo = dir / "pipe.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT(errorOnFifo(fifo, [&] { InputFile f(fifo); }), HasSubstr("pipe.png: a FIFO (named pipe), not a regular file"));
  EXPECT_THAT(errorOnFifo(fifo, [&] { loadImage(fifo, 4); }), HasSubstr("pipe.png: a FIFO"));
  EXPECT_THAT(errorOnFifo(fifo, [&] { readInputFile(fifo, "x", 100); }), HasSubstr("pipe.png: a FIFO"));
  try {
    loadImage("/dev/zero", 4);
    ADD_FAILURE() << "/dev/zero decoded";
  } catch (const Error& e) { EXPECT_THAT(e.what(), HasSubstr("/dev/zero: a character device, not a regular file")); }
  try {
    InputFile f(dir);
    ADD_FAILURE() << "a folder opened";
  } catch (const Error& e) { EXPECT_THAT(e.what(), HasSubstr(dir.string() + ": a folder, not a regular file")); }
}

TEST_F(InputFileTest, SizeIsKnownAndBoundedBeforeReading) {
  const fs::path f = dir / "a.txt";
  std::ofstream(f) << "0123456789";
  InputFile in(f, "material library");
  EXPECT_EQ(in.size(), 10u);
  EXPECT_EQ(in.readAll(10), "0123456789");
  try {
    readInputFile(f, "material library", 9);
    ADD_FAILURE() << "read past the limit";
  } catch (const Error& e) { EXPECT_THAT(e.what(), HasSubstr("a.txt: material library of 10 bytes; the limit is")); }
  // A sparse file of 4 GiB is refused by its size, not read.
  const fs::path big = dir / "big.mtl";
  std::ofstream(big).close();
  fs::resize_file(big, uint64_t(4) << 30);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(readInputFile(big, "material library", uint64_t(64) << 20), Error);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
}

// A PNG header declaring 30000² pixels with a few bytes of data is refused before its texels are made.
TEST_F(InputFileTest, ImageDimensionsAreCheckedAgainstTheFileSize) {
  ImageRGBA8 img{4, 4, std::vector<uint8_t>(64, 200)};
  const fs::path png = dir / "small.png";
  savePng(png, img);
  std::string bytes;
  {
    std::ifstream in(png, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // IHDR's width and height are bytes 16..23, big-endian; its CRC (bytes 29..32) covers bytes 12..28.
  for (int k : {16, 20}) bytes[k] = 0, bytes[k + 1] = 0, bytes[k + 2] = char(0x75), bytes[k + 3] = char(0x30);  // 30000
  uint32_t crc = 0xFFFFFFFFu;
  for (int i = 12; i < 29; ++i) {
    crc ^= uint8_t(bytes[i]);
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  crc = ~crc;
  for (int b = 0; b < 4; ++b) bytes[29 + b] = char(crc >> (24 - 8 * b));
  const fs::path huge = dir / "huge.png";
  std::ofstream(huge, std::ios::binary) << bytes;
  try {
    loadImage(huge, 4);
    ADD_FAILURE() << "decoded";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("huge.png"));
    EXPECT_THAT(e.what(), HasSubstr("30000x30000 pixels cannot come from a file of"));
  }
}

}  // namespace
}  // namespace rtr
