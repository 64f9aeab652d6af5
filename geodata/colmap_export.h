// COLMAP's text model (https://colmap.github.io/format.html): the one
// writer and reader of cameras.txt, images.txt and points3D.txt in a
// folder, for the adjust stage's colmap/ and the BAL benchmark.
#ifndef ZEBRAGEO_GEODATA_COLMAP_EXPORT_H_
#define ZEBRAGEO_GEODATA_COLMAP_EXPORT_H_

#include <string>

#include "survey/colmap_model.h"

namespace zebrageo {

// Writes the three files into `folder` (created if needed), each
// atomically; numbers exactly (survey/csv.h's FormatDouble).
void WriteColmapModel(const ColmapModel& model, const std::string& folder);

// Reads them back. Throws InputError naming the file and line of a line
// that is not of its shape, or an image naming an unknown camera or point.
ColmapModel ReadColmapModel(const std::string& folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_COLMAP_EXPORT_H_
