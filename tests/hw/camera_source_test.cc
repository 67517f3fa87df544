#include "saccade/hw/camera_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>
#include <string>
#include <vector>

#include "hw/camera_test_files.h"
#include "image_camera_helpers.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

using testing::DifferentPixels;
using testing::ImreadRgb;
using testing::kOpenCvData;
using testing::kPairNumbers;
using testing::MatOf;
using testing::PatternFrame;
using testing::SampleName;
using testing::WriteSequence;
namespace fs = std::filesystem;

class CameraSourceTest : public testing::TempDirTest {};

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The message of the HardwareError that `open` throws; fails the test when it throws none.
template <typename F>
std::string HardwareMessage(F&& open) {
  try {
    open();
  } catch (const HardwareError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no HardwareError";
  return "";
}

std::unique_ptr<CameraSource> Open(const std::string& name, const std::string& uri,
                                   double fps = 0.0, bool loop = false) {
  CameraSourceSpec spec;
  spec.name = name;
  spec.uri = uri;
  spec.fps = fps;
  spec.loop = loop;
  return OpenCameraSource(spec);
}

// Writes PatternFrame(0..count-1) as an MJPG AVI at `fps`; returns its path.
fs::path WriteVideo(const fs::path& path, int count, double fps, cv::Size size) {
  cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, size);
  if (!writer.isOpened()) {
    // Debian's OpenCV has FFmpeg; its own MJPEG writer is the fallback.
    writer.open(path.string(), cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                fps, size);
  }
  EXPECT_TRUE(writer.isOpened()) << "cannot write " << path;
  for (int i = 0; i < count; ++i) writer.write(PatternFrame(i, size));
  return path;
}

// Every frame of a video as OpenCV decodes it (RGB), with its CAP_PROP_POS_MSEC.
struct DecodedVideo {
  std::vector<cv::Mat> frames;
  std::vector<double> msec;
  std::string backend;
};

DecodedVideo DecodeWithOpenCv(const fs::path& path) {
  DecodedVideo video;
  cv::VideoCapture capture(path.string());
  if (!capture.isOpened()) capture.open(path.string(), cv::CAP_OPENCV_MJPEG);
  EXPECT_TRUE(capture.isOpened()) << path;
  video.backend = capture.isOpened() ? capture.getBackendName() : "";
  cv::Mat bgr;
  while (capture.read(bgr)) {
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    video.frames.push_back(rgb);
    video.msec.push_back(capture.get(cv::CAP_PROP_POS_MSEC));
  }
  return video;
}

void ExpectIdentityPose(const ImageMetadata& meta) {
  const geometry::Pose* X_WC = geometry::FindCameraPose(meta);
  ASSERT_NE(X_WC, nullptr);
  EXPECT_TRUE(X_WC->matrix() == Eigen::Matrix4d::Identity()) << X_WC->matrix();
  EXPECT_FALSE(meta.has_joints);
}

// ---------------------------------------------------------------------------------------
// The OpenCV this is built against.

TEST(OpenCvVideoIo, HasTheBackendsTheSourcesUse) {
  std::string all;
  for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getBackends()) {
    all += std::string(all.empty() ? "" : " ") + cv::videoio_registry::getBackendName(api);
  }
  std::string writers;
  for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getWriterBackends()) {
    writers += std::string(writers.empty() ? "" : " ") + cv::videoio_registry::getBackendName(api);
  }
  std::printf("OpenCV %s videoio backends: %s; writers: %s; libdc1394: %s\n", CV_VERSION,
              all.c_str(), writers.c_str(), IidcSupported() ? "yes" : "no");
  ::testing::Test::RecordProperty("videoio_backends", all);
  EXPECT_TRUE(cv::videoio_registry::hasBackend(cv::CAP_IMAGES)) << all;
  EXPECT_TRUE(cv::videoio_registry::hasBackend(cv::CAP_OPENCV_MJPEG)) << all;
}

// ---------------------------------------------------------------------------------------
// Image lists: OpenCV's stereo_calib.xml.

TEST_F(CameraSourceTest, ListTakesEveryOtherEntryOfStereoCalibXmlWithIntrinsicsYml) {
  const fs::path intrinsics = kOpenCvData / "intrinsics.yml";
  ASSERT_TRUE(fs::exists(kOpenCvData / "stereo_calib.xml")) << "installed by opencv-doc";
  for (const int index : {1, 2}) {
    CameraSourceSpec spec;
    spec.name = index == 1 ? "left" : "right";
    spec.uri = "list:stereo_calib.xml";
    spec.base_dir = kOpenCvData.string();
    spec.calibration = "intrinsics.yml";
    spec.calibration_index = index;
    spec.first = index - 1;
    spec.every = 2;
    spec.fps = 15;
    const auto source = OpenCameraSource(spec);
    EXPECT_EQ(source->name(), spec.name);
    EXPECT_FALSE(source->live());
    ASSERT_TRUE(source->calibrated());

    // K and distortion exactly as OpenCV reads them from intrinsics.yml.
    cv::FileStorage storage(intrinsics.string(), cv::FileStorage::READ);
    cv::Mat K, D;
    storage[index == 1 ? "M1" : "M2"] >> K;
    storage[index == 1 ? "D1" : "D2"] >> D;
    ASSERT_EQ(K.type(), CV_64F);
    ASSERT_EQ(D.total(), 5u);
    std::vector<double> expected_distortion(D.begin<double>(), D.end<double>());
    expected_distortion.resize(8, 0.0);  // k4 k5 k6: zero, as the simulated cameras give 8

    for (size_t i = 0; i < kPairNumbers.size(); ++i) {
      const std::shared_ptr<Image> image = source->Grab();
      ASSERT_NE(image, nullptr) << "frame " << i;
      const fs::path file = kOpenCvData / SampleName(spec.name.c_str(), kPairNumbers[i]);
      EXPECT_EQ(image->format(), PixelFormat::kRgb8);
      EXPECT_EQ(DifferentPixels(MatOf(*image), ImreadRgb(file)), 0) << file;
      const ImageMetadata& meta = image->metadata();
      EXPECT_EQ(meta.camera, spec.name);
      EXPECT_EQ(meta.frame_index, static_cast<int64_t>(i));
      EXPECT_EQ(meta.time, static_cast<double>(i) / 15.0);
      for (int k = 0; k < 9; ++k)
        EXPECT_EQ(testing_helpers::KAt(meta, k), K.at<double>(k / 3, k % 3)) << "K " << k;
      EXPECT_EQ(testing_helpers::DistortionName(meta), "radtan");
      EXPECT_EQ(testing_helpers::Coefficients(meta), expected_distortion);
      ExpectIdentityPose(meta);
    }
    EXPECT_EQ(source->Grab(), nullptr) << "13 frames, then the end";
    EXPECT_EQ(source->Grab(), nullptr) << "and it stays there";
    EXPECT_EQ(source->model().intrinsics().width(), 640);
    EXPECT_EQ(source->model().intrinsics().height(), 480);
  }
}

TEST_F(CameraSourceTest, TextListResolvesEntriesAgainstItsFolderAndSkipsComments) {
  WriteSequence(Path("frames"), "f", 3, {16, 12});
  WriteText("frames/list.txt",
            "# three frames, backwards\n\nf_0002.png\n  f_0001.png  \n# skip\nf_0000.png\n");
  CameraSourceSpec spec;
  spec.name = "cam";
  spec.uri = "list:frames/list.txt";
  spec.base_dir = dir_.string();
  const auto source = OpenCameraSource(spec);
  for (const int expected : {2, 1, 0}) {
    const auto image = source->Grab();
    ASSERT_NE(image, nullptr);
    cv::Mat rgb;
    cv::cvtColor(PatternFrame(expected, {16, 12}), rgb, cv::COLOR_BGR2RGB);
    EXPECT_EQ(DifferentPixels(MatOf(*image), rgb), 0) << "frame " << expected;
    // Still images without fps: 1 s apart.
    EXPECT_EQ(image->metadata().time, static_cast<double>(2 - expected));
  }
  EXPECT_EQ(source->Grab(), nullptr);
  EXPECT_FALSE(source->calibrated());
}

// ---------------------------------------------------------------------------------------
// Image sequences (printf patterns, CAP_IMAGES) and still images.

TEST_F(CameraSourceTest, SequencePatternDeliversItsFramesInOrder) {
  const cv::Size size(24, 18);
  const std::string pattern = WriteSequence(Path("seq"), "left", 5, size);
  const auto source = Open("left", pattern, 30.0);
  for (int i = 0; i < 5; ++i) {
    const auto image = source->Grab();
    ASSERT_NE(image, nullptr) << i;
    char name[32];
    std::snprintf(name, sizeof(name), "left_%04d.png", i);
    EXPECT_EQ(DifferentPixels(MatOf(*image), ImreadRgb(Path("seq") / name)), 0) << name;
    EXPECT_EQ(image->metadata().frame_index, i);
    EXPECT_EQ(image->metadata().time, i / 30.0);
    EXPECT_EQ(image->width(), 24);
  }
  EXPECT_EQ(source->Grab(), nullptr);
  // Uncalibrated: a nominal pinhole at the frames' size, no distortion.
  EXPECT_FALSE(source->calibrated());
  EXPECT_EQ(source->model().intrinsics().width(), 24);
  EXPECT_EQ(source->model().intrinsics().height(), 18);
  EXPECT_EQ(source->model().intrinsics().fx(), 24.0);
  EXPECT_EQ(source->model().intrinsics().cx(), 11.5);
}

TEST_F(CameraSourceTest, GrayAndSixteenBitFramesBecomeRgb) {
  fs::create_directories(Path("gray"));
  cv::Mat gray(6, 8, CV_8UC1), deep(6, 8, CV_16UC1);
  cv::randu(gray, 0, 256);
  cv::randu(deep, 0, 65536);
  cv::imwrite(Path("gray/g_0000.png").string(), gray);
  cv::imwrite(Path("gray/g_0001.png").string(), deep);
  const auto source = Open("mono", Path("gray/g_%04d.png").string());
  const auto first = source->Grab();
  ASSERT_NE(first, nullptr);
  cv::Mat expected;
  cv::cvtColor(gray, expected, cv::COLOR_GRAY2RGB);
  EXPECT_EQ(DifferentPixels(MatOf(*first), expected), 0);
  const auto second = source->Grab();
  ASSERT_NE(second, nullptr);
  cv::Mat deep8;
  deep.convertTo(deep8, CV_8U, 1.0 / 256.0);  // the top 8 bits, rounded
  cv::cvtColor(deep8, expected, cv::COLOR_GRAY2RGB);
  EXPECT_EQ(DifferentPixels(MatOf(*second), expected), 0);
}

TEST_F(CameraSourceTest, StillImageIsOneFrameOrLoopsForever) {
  const fs::path file = kOpenCvData / "left01.jpg";
  auto once = Open("still", file.string());
  ASSERT_NE(once->Grab(), nullptr);
  EXPECT_EQ(once->Grab(), nullptr);

  auto forever = Open("still", "file:" + file.string(), 10.0, true);
  for (int i = 0; i < 4; ++i) {
    const auto image = forever->Grab();
    ASSERT_NE(image, nullptr);
    EXPECT_EQ(image->metadata().frame_index, i);
    EXPECT_EQ(image->metadata().time, i / 10.0);
    EXPECT_EQ(DifferentPixels(MatOf(*image), ImreadRgb(file)), 0);
  }
}

TEST_F(CameraSourceTest, FirstAndEverySelectFramesOfASequence) {
  const std::string pattern = WriteSequence(Path("seq"), "s", 7, {8, 8});
  CameraSourceSpec spec;
  spec.name = "odd";
  spec.uri = pattern;
  spec.first = 1;
  spec.every = 3;
  const auto source = OpenCameraSource(spec);
  for (const int expected : {1, 4}) {
    const auto image = source->Grab();
    ASSERT_NE(image, nullptr);
    cv::Mat rgb;
    cv::cvtColor(PatternFrame(expected, {8, 8}), rgb, cv::COLOR_BGR2RGB);
    EXPECT_EQ(DifferentPixels(MatOf(*image), rgb), 0) << expected;
  }
  EXPECT_EQ(source->Grab(), nullptr) << "7 is past the end";
}

// ---------------------------------------------------------------------------------------
// Video files.

TEST_F(CameraSourceTest, VideoFramesAndTimesAreWhatOpenCvDecodes) {
  const fs::path video = WriteVideo(Path("clip.avi"), 6, 10.0, {32, 24});
  const DecodedVideo reference = DecodeWithOpenCv(video);
  ASSERT_EQ(reference.frames.size(), 6u) << reference.backend;
  const auto source = Open("cam", video.string());
  for (size_t i = 0; i < reference.frames.size(); ++i) {
    const auto image = source->Grab();
    ASSERT_NE(image, nullptr) << i;
    EXPECT_EQ(DifferentPixels(MatOf(*image), reference.frames[i]), 0) << "frame " << i;
    // The file's own time (FFmpeg: the frame's presentation time, 0, 0.1, ...).
    EXPECT_EQ(image->metadata().time, reference.msec[i] / 1000.0) << "frame " << i;
    EXPECT_EQ(image->metadata().frame_index, static_cast<int64_t>(i));
  }
  EXPECT_EQ(source->Grab(), nullptr);
  if (reference.backend == "FFMPEG") {
    EXPECT_DOUBLE_EQ(reference.msec[3], 300.0);
  }

  // With fps, the time is frame_index / fps instead.
  const auto at_25 = Open("cam", video.string(), 25.0);
  for (int i = 0; i < 6; ++i) {
    const auto image = at_25->Grab();
    ASSERT_NE(image, nullptr);
    EXPECT_EQ(image->metadata().time, i / 25.0);
  }
}

TEST_F(CameraSourceTest, VideoLoopsWithTimeContinuingAndStopsWithoutLoop) {
  const fs::path video = WriteVideo(Path("loop.avi"), 4, 20.0, {16, 16});
  const DecodedVideo reference = DecodeWithOpenCv(video);
  ASSERT_EQ(reference.frames.size(), 4u);

  const auto once = Open("cam", video.string());
  for (int i = 0; i < 4; ++i) ASSERT_NE(once->Grab(), nullptr);
  EXPECT_EQ(once->Grab(), nullptr);
  EXPECT_EQ(once->Grab(), nullptr);

  const auto looping = Open("cam", video.string(), 0.0, true);
  double previous = -1.0;
  for (int i = 0; i < 10; ++i) {
    const auto image = looping->Grab();
    ASSERT_NE(image, nullptr) << i;
    EXPECT_EQ(image->metadata().frame_index, i);
    EXPECT_EQ(DifferentPixels(MatOf(*image), reference.frames[static_cast<size_t>(i % 4)]), 0)
        << "frame " << i;
    // Each pass starts one frame period (1/20 s) after the last frame of the one before.
    const double pass = i / 4;
    const double expected = pass * (reference.msec[3] / 1000.0 + 1.0 / 20.0) +
                            reference.msec[static_cast<size_t>(i % 4)] / 1000.0;
    EXPECT_NEAR(image->metadata().time, expected, 1e-12) << "frame " << i;
    EXPECT_GT(image->metadata().time, previous);
    previous = image->metadata().time;
  }
}

TEST_F(CameraSourceTest, LatchThenRetrieveIsGrab) {
  const std::string pattern = WriteSequence(Path("seq"), "s", 3, {8, 8});
  const auto source = Open("cam", pattern, 10.0);
  EXPECT_EQ(source->Retrieve(), nullptr) << "nothing latched";
  ASSERT_TRUE(source->Latch());
  const auto first = source->Retrieve();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->metadata().frame_index, 0);
  EXPECT_EQ(source->Retrieve(), nullptr) << "retrieved already";
  ASSERT_TRUE(source->Latch());
  ASSERT_TRUE(source->Latch()) << "latching again drops the frame latched before";
  const auto third = source->Retrieve();
  ASSERT_NE(third, nullptr);
  cv::Mat rgb;
  cv::cvtColor(PatternFrame(2, {8, 8}), rgb, cv::COLOR_BGR2RGB);
  EXPECT_EQ(DifferentPixels(MatOf(*third), rgb), 0);
  EXPECT_EQ(third->metadata().frame_index, 1) << "indices count delivered frames";
  EXPECT_FALSE(source->Latch());
  EXPECT_EQ(source->Retrieve(), nullptr);
}

// ---------------------------------------------------------------------------------------
// Calibration.

TEST_F(CameraSourceTest, OneCameraCalibrationFileGivesTheModel) {
  CameraSourceSpec spec;
  spec.name = "left";
  spec.uri = (kOpenCvData / "left01.jpg").string();
  spec.calibration = (kOpenCvData / "left_intrinsics.yml").string();
  const auto source = OpenCameraSource(spec);
  EXPECT_TRUE(source->calibrated());
  EXPECT_EQ(source->model(), geometry::ReadCameraCalibration(spec.calibration).model);
  const auto image = source->Grab();
  ASSERT_NE(image, nullptr);
  EXPECT_EQ(testing_helpers::KAt(image->metadata(), 0), 5.3591573396163199e+02);
  EXPECT_EQ(testing_helpers::Coefficients(image->metadata())[4], 2.3839153080878486e-01);
}

TEST_F(CameraSourceTest, CalibrationSizeMismatchNamesCameraSizesAndFile) {
  // left_intrinsics.yml is for 640x480; these frames are 32x24.
  const std::string pattern = WriteSequence(Path("small"), "s", 2, {32, 24});
  CameraSourceSpec spec;
  spec.name = "left";
  spec.uri = pattern;
  spec.calibration = (kOpenCvData / "left_intrinsics.yml").string();
  const std::string message = HardwareMessage([&] { OpenCameraSource(spec); });
  EXPECT_TRUE(Contains(message, "camera left")) << message;
  EXPECT_TRUE(Contains(message, "32x24")) << message;
  EXPECT_TRUE(Contains(message, "640x480")) << message;
  EXPECT_TRUE(Contains(message, spec.calibration)) << message;
}

TEST_F(CameraSourceTest, FrameOfAnotherSizeMidStreamNamesTheFrame) {
  // intrinsics.yml has no size: it takes the first frame's (640x480); the third is 32x24.
  fs::copy_file(kOpenCvData / "left01.jpg", Path("a.jpg"));
  fs::copy_file(kOpenCvData / "left02.jpg", Path("b.jpg"));
  cv::imwrite(Path("small.png").string(), PatternFrame(0, {32, 24}));
  WriteText("list.txt", "a.jpg\nb.jpg\nsmall.png\n");
  CameraSourceSpec spec;
  spec.name = "left";
  spec.uri = "list:" + Path("list.txt").string();
  spec.calibration = (kOpenCvData / "intrinsics.yml").string();
  spec.calibration_index = 1;
  const auto source = OpenCameraSource(spec);
  ASSERT_NE(source->Grab(), nullptr);
  ASSERT_NE(source->Grab(), nullptr);
  const std::string message = HardwareMessage([&] { source->Grab(); });
  EXPECT_TRUE(Contains(message, "camera left")) << message;
  EXPECT_TRUE(Contains(message, "frame 2 is 32x24")) << message;
  EXPECT_TRUE(Contains(message, "640x480")) << message;
  EXPECT_TRUE(Contains(message, "intrinsics.yml")) << message;
}

TEST_F(CameraSourceTest, MissingCalibrationKeyNamesFileLineAndKey) {
  // intrinsics.yml without D2: reading camera 2 fails on D2, camera 1 does not need it.
  std::ifstream in(kOpenCvData / "intrinsics.yml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t d2 = text.find("D2:");
  ASSERT_NE(d2, std::string::npos);
  text.replace(d2, 3, "Dx:");
  const fs::path calibration = WriteText("no_d2.yml", text);
  CameraSourceSpec spec;
  spec.name = "right";
  spec.uri = "list:" + (kOpenCvData / "stereo_calib.xml").string();
  spec.first = 1;
  spec.every = 2;
  spec.calibration = calibration.string();
  spec.calibration_index = 2;
  const std::string message = HardwareMessage([&] { OpenCameraSource(spec); });
  EXPECT_TRUE(Contains(message, "camera right")) << message;
  EXPECT_TRUE(Contains(message, calibration.string() + ": D2: missing key")) << message;

  spec.calibration_index = 1;
  EXPECT_NO_THROW(OpenCameraSource(spec));

  // A malformed value: file, line and key.
  text.replace(text.find("5.3480326845051309e+02"), 22, "oops");
  const fs::path bad = WriteText("bad.yml", text);
  spec.calibration = bad.string();
  const std::string bad_message = HardwareMessage([&] { OpenCameraSource(spec); });
  EXPECT_TRUE(Contains(bad_message, bad.string() + ":6: M1.data[0]")) << bad_message;

  spec.calibration = Path("missing.yml").string();
  const std::string missing = HardwareMessage([&] { OpenCameraSource(spec); });
  EXPECT_TRUE(Contains(missing, "camera right")) << missing;
  EXPECT_TRUE(Contains(missing, Path("missing.yml").string() + ": file not found")) << missing;
}

// ---------------------------------------------------------------------------------------
// Errors when opening.

TEST_F(CameraSourceTest, MissingFilesNameTheCameraAndTheFile) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {Path("nothere.avi").string(), "file not found"},
      {Path("nothere.png").string(), "file not found"},
      {"list:" + Path("nothere.txt").string(), "file not found"},
      {Path("nodir/f_%04d.png").string(), "not found"},
      {Path("f_%04d.png").string(), "no image matches the pattern"},
  };
  for (const auto& [uri, what] : cases) {
    const std::string message = HardwareMessage([&] { Open("left", uri); });
    EXPECT_TRUE(Contains(message, "camera left (" + uri + ")")) << message;
    EXPECT_TRUE(Contains(message, what)) << message;
  }
  // A file that is no video.
  WriteText("notes.avi", "not a video");
  const std::string message = HardwareMessage([&] { Open("left", Path("notes.avi").string()); });
  EXPECT_TRUE(Contains(message, "not a video OpenCV can read")) << message;
}

TEST_F(CameraSourceTest, ListProblemsNameTheEntry) {
  cv::imwrite(Path("good.png").string(), PatternFrame(0, {8, 8}));
  WriteText("fake.png", "not an image");
  WriteText("missing.txt", "good.png\n\ngone.png\n");
  std::string message =
      HardwareMessage([&] { Open("cam", "list:" + Path("missing.txt").string()); });
  EXPECT_TRUE(Contains(message, "camera cam")) << message;
  EXPECT_TRUE(Contains(message, Path("missing.txt").string() + ":3: entry 'gone.png'")) << message;
  EXPECT_TRUE(Contains(message, "file not found")) << message;

  WriteText("fake.txt", "good.png\nfake.png\n");
  message = HardwareMessage([&] { Open("cam", "list:" + Path("fake.txt").string()); });
  EXPECT_TRUE(Contains(message, ":2: entry 'fake.png'")) << message;
  EXPECT_TRUE(Contains(message, "not an image")) << message;

  WriteText("empty.txt", "# nothing\n\n");
  message = HardwareMessage([&] { Open("cam", "list:" + Path("empty.txt").string()); });
  EXPECT_TRUE(Contains(message, "empty list")) << message;

  WriteText(
      "nokey.xml",
      "<?xml "
      "version=\"1.0\"?>\n<opencv_storage>\n<images>\"good.png\"</images>\n</opencv_storage>\n");
  message = HardwareMessage([&] { Open("cam", "list:" + Path("nokey.xml").string()); });
  EXPECT_TRUE(Contains(message, "missing key imagelist")) << message;

  WriteText("seq.xml",
            "<?xml "
            "version=\"1.0\"?>\n<opencv_storage>\n<imagelist>\n\"good.png\"\n\"gone.png\"\n</"
            "imagelist>\n</opencv_storage>\n");
  message = HardwareMessage([&] { Open("cam", "list:" + Path("seq.xml").string()); });
  EXPECT_TRUE(Contains(message, "imagelist[1]: entry 'gone.png'")) << message;

  WriteText("ok.txt", "good.png\ngood.png\n");
  CameraSourceSpec spec;
  spec.name = "cam";
  spec.uri = "list:" + Path("ok.txt").string();
  spec.first = 5;
  message = HardwareMessage([&] { OpenCameraSource(spec); });
  EXPECT_TRUE(Contains(message, "no frame after skipping the first 5")) << message;
}

TEST_F(CameraSourceTest, UnknownSchemeNamesTheSchemeAndTheForms) {
  const std::string message = HardwareMessage([&] { Open("left", "rtsp://192.168.0.9/stream"); });
  EXPECT_TRUE(Contains(message, "camera left (rtsp://192.168.0.9/stream)")) << message;
  EXPECT_TRUE(Contains(message, "unknown scheme 'rtsp'")) << message;
  EXPECT_TRUE(Contains(message, "v4l2:")) << message;
  const std::string empty = HardwareMessage([&] { Open("left", "v4l2:"); });
  EXPECT_TRUE(Contains(empty, "nothing after 'v4l2:'")) << empty;
}

// A live source without a camera: GStreamer's test pattern at 30 fps (Debian's
// gstreamer1.0-plugins-base, installed by scripts/setup.sh).
constexpr char kTestPattern[] =
    "gstreamer:videotestsrc pattern=colors num-buffers=4 ! "
    "video/x-raw,format=BGR,width=64,height=48,"
    "framerate=30/1 ! appsink";

TEST_F(CameraSourceTest, GStreamerPipelineIsALiveSourceStampedByTheSteadyClock) {
  std::unique_ptr<CameraSource> source;
  try {
    source = Open("live", kTestPattern);
  } catch (const HardwareError& e) {
    GTEST_SKIP() << "GStreamer's videotestsrc is missing (gstreamer1.0-plugins-base): " << e.what();
  }
  // The reference: the same pipeline through OpenCV alone.
  cv::VideoCapture capture(std::string(kTestPattern).substr(10), cv::CAP_GSTREAMER);
  cv::Mat bgr, expected;
  ASSERT_TRUE(capture.read(bgr));
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2RGB);

  EXPECT_TRUE(source->live());
  EXPECT_EQ(source->model().intrinsics().width(), 64);
  const auto opened = std::chrono::steady_clock::now();
  double previous = -1.0;
  // Four buffers: the first was read when opening (the size) and dropped, as live frames go
  // stale; three remain, then the stream ends.
  for (int i = 0; i < 3; ++i) {
    const auto image = source->Grab();
    ASSERT_NE(image, nullptr) << i;
    const double since_epoch =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - source->epoch()).count();
    EXPECT_EQ(image->metadata().frame_index, i);
    EXPECT_GT(image->metadata().time, previous);
    EXPECT_LE(image->metadata().time, since_epoch);
    EXPECT_GE(image->metadata().time,
              std::chrono::duration<double>(opened - source->epoch()).count());
    previous = image->metadata().time;
    // videotestsrc's colour spectrum is the same in every frame (SMPTE bars have noise).
    EXPECT_EQ(DifferentPixels(MatOf(*image), expected), 0) << i;
    ExpectIdentityPose(image->metadata());
  }
  EXPECT_EQ(source->Grab(), nullptr) << "the pipeline's end of stream ends the source";
}

TEST_F(CameraSourceTest, DevicesThatAreNotThereSaySo) {
  // No V4L2 device has this number.
  std::string message = HardwareMessage([&] { Open("left", "v4l2:/dev/video9999"); });
  EXPECT_TRUE(Contains(message, "camera left (v4l2:/dev/video9999)")) << message;
  EXPECT_TRUE(Contains(message, "no such device")) << message;
  message = HardwareMessage([&] { Open("left", "v4l2:9999"); });
  EXPECT_TRUE(Contains(message, "/dev/video9999")) << message;

  if (cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER)) {
    message = HardwareMessage([&] { Open("left", "gstreamer:saccadenosuchelement ! appsink"); });
    EXPECT_TRUE(Contains(message, "camera left (gstreamer:saccadenosuchelement ! appsink)"))
        << message;
    EXPECT_TRUE(Contains(message, "cannot start it")) << message;
  }
  message = HardwareMessage([&] { Open("left", "gstreamer:videotestsrc ! fakesink"); });
  EXPECT_TRUE(Contains(message, "appsink")) << message;
}

TEST_F(CameraSourceTest, IidcCameraThatIsNotThereNamesTheGuid) {
  // No IEEE 1394 camera is plugged into a test machine.
  const std::string message = HardwareMessage([&] { Open("left", "iidc:0x00b09d0100a01a9a"); });
  EXPECT_TRUE(Contains(message, "camera left (iidc:0x00b09d0100a01a9a)")) << message;
  if (IidcSupported()) {
    EXPECT_TRUE(Contains(message, "no IIDC camera found")) << message;
    EXPECT_TRUE(Contains(message, "GUID 0x00b09d0100a01a9a")) << message;
    const std::string by_index = HardwareMessage([&] { Open("left", "iidc:1"); });
    EXPECT_TRUE(Contains(by_index, "index 1")) << by_index;
    EXPECT_TRUE(Contains(by_index, "no IIDC camera found")) << by_index;
  } else {
    EXPECT_TRUE(Contains(message, "no libdc1394")) << message;
  }
  const std::string bad = HardwareMessage([&] { Open("left", "iidc:left-camera"); });
  EXPECT_TRUE(Contains(bad, "expected a GUID in hex")) << bad;
}

TEST_F(CameraSourceTest, InvalidSpecNamesTheField) {
  struct Case {
    void (*edit)(CameraSourceSpec*);
    std::string field;
  };
  const std::vector<Case> cases = {
      {[](CameraSourceSpec* s) { s->name.clear(); }, "name:"},
      {[](CameraSourceSpec* s) { s->uri.clear(); }, "uri:"},
      {[](CameraSourceSpec* s) { s->calibration_index = 3; }, "calibration_index: expected 0"},
      {[](CameraSourceSpec* s) { s->calibration_index = 1; }, "no calibration is given"},
      {[](CameraSourceSpec* s) { s->fps = -1; }, "fps:"},
      {[](CameraSourceSpec* s) { s->fps = std::nan(""); }, "fps:"},
      {[](CameraSourceSpec* s) { s->first = -1; }, "first:"},
      {[](CameraSourceSpec* s) { s->every = 0; }, "every:"},
  };
  for (const Case& c : cases) {
    CameraSourceSpec spec;
    spec.name = "left";
    spec.uri = (kOpenCvData / "left01.jpg").string();
    std::string error;
    ASSERT_TRUE(spec.IsValid(&error)) << error;
    c.edit(&spec);
    EXPECT_FALSE(spec.IsValid(&error));
    EXPECT_TRUE(Contains(error, c.field)) << error;
    try {
      OpenCameraSource(spec);
      ADD_FAILURE() << "no InvalidArgument for " << c.field;
    } catch (const InvalidArgument& e) {
      EXPECT_TRUE(Contains(e.what(), c.field)) << e.what();
      EXPECT_TRUE(Contains(e.what(), "camera '" + spec.name + "'")) << e.what();
    }
  }
  // first and every select frames of files, not of devices.
  CameraSourceSpec device;
  device.name = "left";
  device.uri = "v4l2:0";
  device.every = 2;
  EXPECT_THROW(OpenCameraSource(device), InvalidArgument);
}

}  // namespace
}  // namespace saccade::hw
