// CIE standard tables (colour matching functions, illuminant D65), 360-830 nm
// in 5 nm steps: what spectral transport and the RGB-to-spectrum fit integrate against.
#pragma once

namespace tessera {

constexpr int kCieSamples = 95;  // 360, 365, ..., 830 nm
constexpr double kCieLambdaMin = 360.0, kCieLambdaStep = 5.0;

extern const float kCie1931Xyz[kCieSamples][3];
extern const float kCieD65[kCieSamples];

// A table above at lambda (nm), linear between its samples, its end values
// beyond them; `stride` floats between samples (3 for one matching function).
double cie_table_at(const float* table, int stride, double lambda);

}  // namespace tessera
