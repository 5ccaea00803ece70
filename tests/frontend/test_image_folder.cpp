// The EuRoC image-folder reader (frontend/image_folder.hpp): what it reads
// and each refusal, on small PNGs written to a scratch folder.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <posefuse/frontend/image_folder.hpp>

#include "support/temp_dir.hpp"

namespace pf = posefuse::frontend;

namespace {

// A folder with data.csv `csv` and 40x30 grey PNGs named `names`.
void make_folder(const posefuse::test::TempDir& dir, const std::string& csv, std::initializer_list<const char*> names,
                 int width = 40, int height = 30) {
  std::filesystem::create_directories(dir.path() / "data");
  for (const char* n : names) {
    cv::Mat img(height, width, CV_8UC1);
    cv::randu(img, 0, 255);
    REQUIRE(cv::imwrite((dir.path() / "data" / n).string(), img));
  }
  (void)dir.write("data.csv", csv);
}

}  // namespace

TEST_CASE("Image folder: data.csv and the images are read", "[frontend]") {
  posefuse::test::TempDir dir("frontend-folder");
  make_folder(dir, "#timestamp [ns],filename\n\n100,a.png\n 200 , b.png\r\n300,c.png\n", {"a.png", "b.png", "c.png"});
  const pf::EurocImageFolder folder(dir.path(), 40, 30);
  REQUIRE(folder.size() == 3);
  CHECK(folder.entries()[0].t_ns == 100);
  CHECK(folder.entries()[1].t_ns == 200);
  CHECK(folder.entries()[1].file == dir.path() / "data" / "b.png");
  CHECK(folder.entries()[2].line == 5);
  const cv::Mat img = folder.image(2);
  CHECK(img.type() == CV_8UC1);
  CHECK(img.cols == 40);
  CHECK(img.rows == 30);
  CHECK_THROWS_AS(folder.image(3), posefuse::invalid_argument);
  // 0 x 0: any size.
  CHECK(pf::EurocImageFolder(dir.path(), 0, 0).image(0).cols == 40);
}

TEST_CASE("Image folder: a missing image is refused naming it and its data.csv line", "[frontend]") {
  posefuse::test::TempDir dir("frontend-folder");
  make_folder(dir, "#timestamp [ns],filename\n100,a.png\n200,missing.png\n", {"a.png"});
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30),
                    Catch::Contains("data.csv:3:") && Catch::Contains("missing.png") &&
                        Catch::Contains("does not exist"));
}

TEST_CASE("Image folder: a stamp that goes back is refused naming both lines", "[frontend]") {
  posefuse::test::TempDir dir("frontend-folder");
  make_folder(dir, "#timestamp [ns],filename\n100,a.png\n300,b.png\n200,c.png\n", {"a.png", "b.png", "c.png"});
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30),
                    Catch::Contains("data.csv:4:") && Catch::Contains("earlier") && Catch::Contains("line 3"));
  posefuse::test::TempDir dir2("frontend-folder");
  make_folder(dir2, "100,a.png\n100,b.png\n", {"a.png", "b.png"});
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir2.path(), 40, 30),
                    Catch::Contains("data.csv:2:") && Catch::Contains("repeats"));
}

TEST_CASE("Image folder: an image of the wrong size is refused naming it and both sizes", "[frontend]") {
  posefuse::test::TempDir dir("frontend-folder");
  make_folder(dir, "100,a.png\n", {"a.png"}, 64, 48);
  const pf::EurocImageFolder folder(dir.path(), 752, 480);
  CHECK_THROWS_WITH(folder.image(0), Catch::Contains("a.png") && Catch::Contains("64x48") &&
                                         Catch::Contains("752x480"));
}

TEST_CASE("Image folder: malformed data.csv lines and unreadable images are refused", "[frontend]") {
  posefuse::test::TempDir dir("frontend-folder");
  make_folder(dir, "100,a.png\n200,b.png,extra\n", {"a.png", "b.png"});
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30),
                    Catch::Contains("data.csv:2:") && Catch::Contains("2 comma-separated fields"));
  (void)dir.write("data.csv", "1.5e9,a.png\n");
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30), Catch::Contains("data.csv:1:"));
  (void)dir.write("data.csv", "100,../a.png\n");
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30), Catch::Contains("data.csv:1:"));
  (void)dir.write("data.csv", "# only a comment\n");
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30), Catch::Contains("lists no image"));
  std::filesystem::remove(dir.path() / "data.csv");
  CHECK_THROWS_WITH(pf::EurocImageFolder(dir.path(), 40, 30), Catch::Contains("data.csv"));
  // A file that is not an image.
  (void)dir.write("data/broken.png", "not a png");
  (void)dir.write("data.csv", "100,broken.png\n");
  const pf::EurocImageFolder folder(dir.path(), 40, 30);
  CHECK_THROWS_WITH(folder.image(0), Catch::Contains("broken.png") && Catch::Contains("cannot be read"));
}
