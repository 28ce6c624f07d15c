#pragma once
/// \file output_set.h
/// \brief Several output files that belong together (an orthophoto with its DSM, class raster
/// and ortho.json; the images of `render`) written as a set: into a staging folder inside the
/// output directory first, moved into place only when all were written, and replacing the
/// previous run's set there, so that a full disk leaves the old set whole and a rerun at another
/// ground sample distance leaves no 1.0 m dsm.tif beside 0.34 m rasters.

#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief A set of files (or folders of files) written into `dir` together.
class OutputSet {
 public:
  /// \param[in] dir the output directory (created when missing)
  /// \param[in] members every name the set may hold (files or folders directly in `dir`): those
  /// of a previous run that this run does not write are removed on commit()
  /// \throws sadsplat::Error naming `dir` when it cannot be created or written
  OutputSet(std::string dir, std::vector<std::string> members);
  /// \brief Removes the staging folder if commit() was not reached (the old set stays).
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// \brief Where to write member `name` now (inside the staging folder).
  std::string path(const std::string& name) const;
  /// \brief The staging folder (for writers that take a folder).
  const std::string& staging() const { return staging_; }
  /// \brief Moves every staged member into `dir` (each by one rename on the same file system)
  /// and removes the previous set's members that were not staged.
  /// \throws sadsplat::Error naming the member that could not be moved
  void commit();

 private:
  std::string dir_;
  std::vector<std::string> members_;
  std::string staging_;
};

}  // namespace io
}  // namespace sadsplat
