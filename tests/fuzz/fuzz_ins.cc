// libFuzzer target: the INS trajectory imports (geodata/trajectory_import.h)
// on the same bytes read as an SBET, a NovAtel ASCII log and a delimited
// export.
#include "geodata/trajectory_import.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    const std::string path = zebrageo::WriteFuzzFile("ins", text);
    try {
      zebrageo::ReadSbet(path, "");
    } catch (const zebrageo::InputError&) {
    }
    try {
      zebrageo::ReadNovatelAscii(path);
    } catch (const zebrageo::InputError&) {
    }
    zebrageo::CsvTrajectoryFormat format;
    format.delimiter = zebrageo::Delimiter::kWhitespace;
    format.time_kind = zebrageo::TimeKind::kUtc;
    zebrageo::ReadTrajectoryCsv(path, format);
  });
  return 0;
}
