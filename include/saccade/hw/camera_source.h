#pragma once
// Real cameras and recorded frames as sources of saccade::Image (DESIGN.md: `hw`), through
// OpenCV's VideoCapture (and libdc1394 for IIDC cameras). OpenCV stays in the .cc files.
//
// A source is named by a URI (CameraSourceSpec::uri):
//   v4l2:/dev/video0, v4l2:0      a V4L2 device, by path or by index (/dev/video<index>)
//   gstreamer:<pipeline>          a GStreamer pipeline ending in appsink, as OpenCV's
//                                 CAP_GSTREAMER takes it ("v4l2src ! videoconvert ! appsink")
//   iidc:<guid>, iidc:<index>     an IIDC camera (IEEE 1394 FireWire, or USB IIDC) through
//                                 libdc1394, in the mode it is set to, each grab taking the
//                                 newest frame of its DMA ring: a 64-bit GUID in hex
//                                 (with or without 0x, more than 4 digits, as dc1394 prints
//                                 it) or the index of the camera on the bus (0, 1, ...). Only
//                                 in builds with libdc1394 (IidcSupported()).
//   list:<file>                   an image list: OpenCV FileStorage (XML, YAML, JSON) with an
//                                 `imagelist` sequence of file names (OpenCV's
//                                 stereo_calib.xml), or a text file with one path per line
//                                 (blank lines and lines starting with # are skipped). Entries
//                                 are relative to the list file's folder.
//   frames/left_%04d.png          a printf pattern: an image sequence (OpenCV's CAP_IMAGES;
//                                 it starts at the first index that exists, 0 or 1)
//   left.png, left.jpg, ...       one still image (a source of one frame; with loop, forever)
//   video.avi, video.mp4, ...     a video file (any other path): OpenCV's FFmpeg backend, else
//                                 its own MJPEG reader (AVI), as this OpenCV has them
//   file:<path>                   a path that would otherwise look like a scheme
// A scheme is letters, digits, '+', '-' or '.' before the first ':', starting with a letter
// and followed by no '/' before the ':'; write "./a:b.avi" for such a file. Relative paths
// (files, lists, patterns, the calibration) resolve against CameraSourceSpec::base_dir.
//
// Frames are PixelFormat::kRgb8 (converted from BGR, BGRA, gray, 16-bit) with their
// ImageMetadata filled as the simulated cameras fill it: camera = the source's name,
// frame_index 0, 1, 2, ... as delivered, time (below), the calibration's camera model
// (geometry/image_camera.h: K and the distortion, coefficients in OpenCV's order), X_WC the
// identity and has_joints false (a component that knows the head fills both).
//
// Time stamps, in seconds:
// - devices (v4l2, gstreamer, iidc): the std::chrono::steady_clock time at which the frame was
//   taken from the driver, counted from the source's epoch() (its opening, unless set). V4L2
//   hands out the oldest of the frames OpenCV has it buffer: grab at the camera's rate or
//   faster, or frames arrive (and are stamped) late. A GStreamer pipeline buffers as its
//   appsink says ("appsink drop=true max-buffers=1" keeps only the newest);
// - files, sequences, lists: frame_index / fps when CameraSourceSpec::fps > 0; else a video's
//   own time stamp (CAP_PROP_POS_MSEC), and for still images (sequences, lists) 1 s per frame
//   (still images carry no time; OpenCV's CAP_IMAGES reports 1 fps too). Looping continues
//   the time: the second pass starts one frame period after the last frame of the first.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"

namespace saccade::hw {

/// What to open: a camera's name, where its frames come from and its calibration.
struct CameraSourceSpec {
  /// The camera's name ("left", "right"): ImageMetadata::camera, and in every error message.
  /// Must not be empty.
  std::string name;
  /// Where the frames come from; the forms are listed at the top of this header.
  std::string uri;
  /// A calibration file read with geometry::ReadCameraCalibration (OpenCV YAML/XML, ROS YAML)
  /// or, with calibration_index 1 or 2, geometry::ReadStereoCameraCalibration. Empty: none
  /// (the source is not calibrated(); model() is a nominal pinhole).
  std::string calibration;
  /// 0: a one-camera file; 1: M1 D1 of a stereo file (the left camera); 2: M2 D2.
  int calibration_index = 0;
  /// Frames per second (> 0) or 0. Files, sequences and lists: the time stamps are
  /// frame_index / fps (else as described above). Devices: the frame rate asked of the device
  /// (V4L2: CAP_PROP_FPS; IIDC: the closest rate its mode has; GStreamer: ignored, write it in
  /// the pipeline's caps). V4L2 devices are also asked for the calibration file's image size
  /// when the file states one.
  double fps = 0.0;
  /// Files, sequences and lists: start again at the first frame at the end. Devices: ignored.
  bool loop = false;
  /// Files, sequences and lists: deliver the frames first, first + every, first + 2 every, ...
  /// (stereo_calib.xml alternates left and right: left is first 0, right first 1, every 2).
  /// Devices reject other values than 0 and 1.
  int first = 0;
  int every = 1;
  /// The folder that relative paths in uri and calibration resolve against; empty: the
  /// working directory.
  std::string base_dir;

  /// True when the fields are in range (name not empty, uri not empty, calibration_index 0, 1
  /// or 2 and 0 unless a calibration is given, fps >= 0 and finite, first >= 0, every >= 1);
  /// else false with the reason (naming the field and value) in *error when error is not null.
  bool IsValid(std::string* error) const;
};

/// A source of frames from one camera. Not thread-safe: one thread grabs.
class CameraSource {
 public:
  virtual ~CameraSource();
  CameraSource(const CameraSource&) = delete;
  CameraSource& operator=(const CameraSource&) = delete;

  /// The camera's name, as in every frame's metadata.
  const std::string& name() const { return name_; }
  /// The URI it was opened with (as given, before base_dir).
  const std::string& uri() const { return uri_; }
  /// The calibrated camera: the calibration's intrinsics and distortion at the frames' size.
  /// Without a calibration, a nominal pinhole at the frames' size (fx = fy = the larger side,
  /// principal point at the image centre, no distortion): use it only for display.
  const geometry::CameraModel& model() const { return model_; }
  /// Whether model() comes from a calibration file.
  bool calibrated() const { return calibrated_; }
  /// True for devices (time stamps from the steady clock), false for files, sequences, lists.
  bool live() const { return live_; }

  /// The instant live time stamps count from: the source's opening, unless set. A StereoSource
  /// gives both its cameras the same epoch so that their time stamps compare.
  std::chrono::steady_clock::time_point epoch() const { return epoch_; }
  void set_epoch(std::chrono::steady_clock::time_point epoch) { epoch_ = epoch; }

  /// The next frame; nullptr at the end of a file, sequence or list (unless loop), and on every
  /// call after that. Throws HardwareError naming the camera and the uri when the device fails,
  /// an image cannot be decoded or a frame's size differs from the calibration's.
  virtual std::shared_ptr<Image> Grab() = 0;

  /// Grab in two steps, for synchronised capture of several cameras (VideoCapture's grab and
  /// retrieve): Latch() takes the next frame from the device and stamps its time, as quickly
  /// as it can, without decoding it; Retrieve() decodes and returns the latched frame (nullptr
  /// when Latch() returned false or nothing is latched). Latch() returns false at the end.
  /// The default takes the whole frame in Latch() (Grab()); devices override both.
  virtual bool Latch();
  virtual std::shared_ptr<Image> Retrieve();

 protected:
  /// For subclasses (including test doubles): the metadata's name, the uri, the model.
  CameraSource(std::string name, std::string uri, const geometry::CameraModel& model,
               bool calibrated, bool live);
  void set_model(const geometry::CameraModel& model, bool calibrated) {
    model_ = model;
    calibrated_ = calibrated;
  }

 private:
  std::string name_;
  std::string uri_;
  geometry::CameraModel model_;
  bool calibrated_ = false;
  bool live_ = false;
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  std::shared_ptr<Image> latched_;
};

/// Opens a source. It reads its first frame (the image size, and a check that frames come):
/// a file's first frame is delivered by the first Grab(), a device's is dropped. Throws
/// InvalidArgument naming the camera and the field for a spec that is not IsValid(), and
/// HardwareError naming the camera and the uri when the source cannot be opened (unknown
/// scheme, missing file, no device, empty list or sequence, a list entry that is missing or
/// not an image, naming the entry), when the calibration file cannot be read (the message
/// contains FileError's "file:line: key: what"), and when the first frame's size is not the
/// calibration's (naming both sizes and the calibration file).
std::unique_ptr<CameraSource> OpenCameraSource(const CameraSourceSpec& spec);

/// Whether this build reads IIDC cameras (iidc: URIs): libdc1394 was found when it was built.
bool IidcSupported();

}  // namespace saccade::hw
