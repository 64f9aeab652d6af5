// synthetic_reconstruction SURVEY RESULTS [SEED [NOISE_M [MAX_RANGE_M]]]
// Writes RESULTS/reconstructed_bands.csv from SURVEY/truth: the truth bands
// fully visible in a stereo pair, in the body frame of the true pose, plus
// noise. For testing `zebrageo match` independently of the reconstruction.
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

#include "tests/registration/synthetic_scene.h"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 6) {
    std::cerr << "usage: synthetic_reconstruction SURVEY RESULTS [SEED "
                 "[NOISE_M [MAX_RANGE_M]]]\n";
    return 2;
  }
  const int seed = argc > 3 ? std::atoi(argv[3]) : 1;
  const double noise = argc > 4 ? std::atof(argv[4]) : 0.015;
  const double range = argc > 5 ? std::atof(argv[5]) : 15.0;
  try {
    const int bands = zebrageo::WriteSyntheticReconstruction(
        argv[1], argv[2], seed, noise, range);
    std::cout << "wrote " << bands << " bands\n";
  } catch (const std::exception& error) {
    std::cerr << "synthetic_reconstruction: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
