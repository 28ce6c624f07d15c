#pragma once
/// \file las_frame.h
/// \brief The frame a model's LAS export takes (`convert`, `extract`), so that a class cloud
/// lies on the maps `ortho` draws: the UTM zone of the run's georeference (exact, through PROJ);
/// without one, the map's local metres (z up, the scene's x made horizontal: the GeoTIFFs' and
/// `ortho --object-clouds`' frame), from the up direction of the scene the run trained on;
/// where no run or scene is found beside the model, the scene's own axes, with a note.

#include <ostream>
#include <string>

#include "sadsplat/geo/las_export.h"

namespace sadsplat {
namespace pipeline {

/// \brief LAS options for the model file (or run directory) `model_path`: its classes and
/// georeference (geo::lasOptionsBeside), and without a georeference the maps' local frame when
/// its folder is a run directory whose scene can be read (a cache is read without its pixels).
/// `notes` (when not null) gets a line when the points stay in the scene's own axes.
/// \throws sadsplat::Error as geo::lasOptionsBeside, or naming run.json when it is damaged
geo::LasExportOptions lasOptionsForModel(const std::string& model_path,
                                         const std::string& classification_map,
                                         std::ostream* notes);

}  // namespace pipeline
}  // namespace sadsplat
