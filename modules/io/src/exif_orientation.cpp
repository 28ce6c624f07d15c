#include "sadsplat/io/exif_orientation.h"

#if SADSPLAT_HAVE_EXIF
#include <libexif/exif-data.h>
#endif

#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {

int readExifOrientation(const std::string& path) {
  requireRegularFile(path);
#if SADSPLAT_HAVE_EXIF
  ExifData* data = exif_data_new_from_file(path.c_str());
  if (data == nullptr) return 1;
  ExifEntry* entry = exif_content_get_entry(data->ifd[EXIF_IFD_0], EXIF_TAG_ORIENTATION);
  int orientation = 1;
  if (entry != nullptr && entry->format == EXIF_FORMAT_SHORT && entry->components == 1) {
    orientation = exif_get_short(entry->data, exif_data_get_byte_order(data));
  }
  exif_data_unref(data);
  return orientation >= 1 && orientation <= 8 ? orientation : 1;
#else
  return 1;
#endif
}

}  // namespace io
}  // namespace sadsplat
