// Seeded random scenes for stress tests of the convolution against the reference: a floor and
// 3–8 objects (boxes, spheres, cylinders, thin walls; some resting on the floor, some raised like
// a table top, some receivers) under 1–3 lights of every shape, some high, some low among or
// under the objects. The same seed writes the same files. Meshes are OBJ with lightmap UVs in
// channel 0 (receivers' charts inside [0, 1], apart); Z up, metres.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace sb::random_scenes {

struct ObjWriter {
  std::ostringstream v, vt, f;
  int vertices = 0, uvs = 0;
  // A quad a, b, c, d (counter-clockwise seen from outside) with UVs over the rectangle lo..hi.
  void quad(const double* a, const double* b, const double* c, const double* d, double u0,
            double v0, double u1, double v1) {
    const double* p[4] = {a, b, c, d};
    const double uv[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
    for (int k = 0; k < 4; ++k) {
      v << "v " << p[k][0] << " " << p[k][1] << " " << p[k][2] << "\n";
      vt << "vt " << uv[k][0] << " " << uv[k][1] << "\n";
    }
    const int b0 = vertices + 1, t0 = uvs + 1;
    f << "f " << b0 << "/" << t0 << " " << b0 + 1 << "/" << t0 + 1 << " " << b0 + 2 << "/" << t0 + 2
      << "\n";
    f << "f " << b0 << "/" << t0 << " " << b0 + 2 << "/" << t0 + 2 << " " << b0 + 3 << "/" << t0 + 3
      << "\n";
    vertices += 4;
    uvs += 4;
  }
  std::string text() const { return v.str() + vt.str() + f.str(); }
};

// A box with half sizes (hx, hy, hz) at (cx, cy, cz) turned by `angle` about Z; its six faces'
// charts in a 3 × 2 grid of UV cells, each with a margin of 0.02.
inline std::string box(double cx, double cy, double cz, double hx, double hy, double hz,
                       double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  auto corner = [&](int i, double* out) {
    const double x = (i & 1 ? hx : -hx), y = (i & 2 ? hy : -hy), z = (i & 4 ? hz : -hz);
    out[0] = cx + c * x - s * y;
    out[1] = cy + s * x + c * y;
    out[2] = cz + z;
  };
  double p[8][3];
  for (int i = 0; i < 8; ++i) corner(i, p[i]);
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  ObjWriter w;
  for (int k = 0; k < 6; ++k) {
    const double u0 = (k % 3) / 3.0 + 0.02, v0 = (k / 3) / 2.0 + 0.02;
    w.quad(p[faces[k][0]], p[faces[k][1]], p[faces[k][2]], p[faces[k][3]], u0, v0,
           u0 + 1 / 3.0 - 0.04, v0 + 0.5 - 0.04);
  }
  return w.text();
}

// A UV sphere (24 × 12) with latitude-longitude UVs.
inline std::string sphere(double cx, double cy, double cz, double r) {
  std::ostringstream out;
  const int nu = 24, nv = 12;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double th = std::numbers::pi * j / nv, ph = 2 * std::numbers::pi * i / nu;
      out << "v " << cx + r * std::sin(th) * std::cos(ph) << " "
          << cy + r * std::sin(th) * std::sin(ph) << " " << cz + r * std::cos(th) << "\n";
      out << "vt " << 0.02 + 0.96 * i / nu << " " << 0.02 + 0.96 * (1.0 - double(j) / nv) << "\n";
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i + 1, b = a + 1, c = a + nu + 1, d = c + 1;
      if (j > 0)
        out << "f " << a << "/" << a << " " << c << "/" << c << " " << b << "/" << b << "\n";
      if (j < nv - 1)
        out << "f " << b << "/" << b << " " << c << "/" << c << " " << d << "/" << d << "\n";
    }
  return out.str();
}

// A closed cylinder (24 sides) standing on z0.
inline std::string cylinder(double cx, double cy, double z0, double r, double h) {
  std::ostringstream out;
  const int n = 24;
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    for (int k = 0; k < 2; ++k)
      out << "v " << cx + r * std::cos(a) << " " << cy + r * std::sin(a) << " " << z0 + k * h
          << "\nvt " << 0.02 + 0.96 * i / n << " " << 0.3 + 0.4 * k << "\n";
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i + 1, b = a + 1, c = a + 2, d = a + 3;
    out << "f " << a << "/" << a << " " << c << "/" << c << " " << d << "/" << d << "\n";
    out << "f " << a << "/" << a << " " << d << "/" << d << " " << b << "/" << b << "\n";
  }
  // Caps as fans about their centres.
  const int base = 2 * (n + 1);
  for (int k = 0; k < 2; ++k) {
    out << "v " << cx << " " << cy << " " << z0 + k * h << "\nvt " << 0.25 + 0.5 * k << " 0.15\n";
    const int centre = base + k + 1;
    for (int i = 0; i < n; ++i) {
      const int a = 2 * i + 1 + k, b = 2 * (i + 1) + 1 + k;
      if (k == 0)
        out << "f " << centre << "/" << centre << " " << b << "/" << b << " " << a << "/" << a
            << "\n";
      else
        out << "f " << centre << "/" << centre << " " << a << "/" << a << " " << b << "/" << b
            << "\n";
    }
  }
  return out.str();
}

// Writes scene `seed` into `folder` (made if missing) and returns its scene.toml.
inline std::filesystem::path write_random_scene(std::uint32_t seed,
                                                const std::filesystem::path& folder,
                                                int resolution) {
  std::filesystem::create_directories(folder);
  std::mt19937 rng(seed);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  std::ostringstream scene;
  scene << "# random scene " << seed
        << " (tests/support/random_scenes.h)\n[bake]\nresolution = " << resolution
        << "\nmethod = \"reference\"\nsamples = 64\n\n";
  auto write = [&](const std::string& name, const std::string& obj, bool receiver) {
    std::ofstream(folder / (name + ".obj")) << obj;
    scene << "[[object]]\nname = \"" << name << "\"\nmesh = \"" << name
          << ".obj\"\nreceiver = " << (receiver ? "true" : "false") << "\n\n";
  };
  {
    ObjWriter floor;
    const double a[3] = {-2, -2, 0}, b[3] = {2, -2, 0}, c[3] = {2, 2, 0}, d[3] = {-2, 2, 0};
    floor.quad(a, b, c, d, 0, 0, 1, 1);
    write("floor", floor.text(), true);
  }
  // Lights first, then objects kept off them.
  struct Ball {
    double x, y, z, r;
  };
  std::vector<Ball> keep_out;
  const int lights = 1 + int(rng() % 3);
  for (int l = 0; l < lights; ++l) {
    const int shape = int(rng() % 3);
    const bool low = rng() % 3 == 0;
    const double x = uniform(-1.2, 1.2), y = uniform(-1.2, 1.2);
    const double z = low ? uniform(0.25, 0.8) : uniform(1.6, 2.6);
    const double size = uniform(0.1, 0.6);
    scene << "[[light]]\nname = \"light" << l << "\"\nposition = [" << x << ", " << y << ", " << z
          << "]\npower = " << uniform(50, 300) << "\n";
    const double nx = uniform(-0.4, 0.4), ny = uniform(-0.4, 0.4);
    if (shape == 0) {
      scene << "shape = \"rectangle\"\nnormal = [" << nx << ", " << ny << ", -1]\nsize = [" << size
            << ", " << size * uniform(0.4, 1.0) << "]\n\n";
    } else if (shape == 1) {
      scene << "shape = \"disk\"\nnormal = [" << nx << ", " << ny
            << ", -1]\nradius = " << 0.5 * size << "\n\n";
    } else {
      scene << "shape = \"sphere\"\nradius = " << 0.3 * size << "\n\n";
    }
    keep_out.push_back({x, y, z, size + 0.1});
  }
  const int objects = 3 + int(rng() % 6);
  for (int k = 0; k < objects; ++k) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const int kind = int(rng() % 5);
      const double x = uniform(-1.5, 1.5), y = uniform(-1.5, 1.5);
      double radius = 0, top = 0, z = 0;
      std::string obj;
      if (kind == 0 || kind == 4) {  // a box on the floor, or raised (a table top)
        const double hx = uniform(0.1, 0.5), hy = uniform(0.1, 0.5);
        const double hz = kind == 0 ? uniform(0.1, 0.6) : uniform(0.02, 0.05);
        z = kind == 0 ? hz : uniform(0.5, 1.0);
        obj = box(x, y, z, hx, hy, hz, uniform(0, 3.14));
        radius = std::hypot(hx, hy, hz);
        top = z + hz;
      } else if (kind == 1) {
        const double r = uniform(0.1, 0.4);
        z = rng() % 2 ? r : uniform(r, 1.5);
        obj = sphere(x, y, z, r);
        radius = r;
        top = z + r;
      } else if (kind == 2) {
        const double r = uniform(0.05, 0.25), h = uniform(0.3, 2.0);
        obj = cylinder(x, y, 0, r, h);
        z = 0.5 * h;
        radius = std::hypot(r, 0.5 * h);
        top = h;
      } else {  // a thin wall
        const double hx = uniform(0.3, 1.0), hz = uniform(0.3, 1.3);
        z = hz;
        obj = box(x, y, z, hx, 0.02, hz, uniform(0, 3.14));
        radius = std::hypot(hx, hz);
        top = 2 * hz;
      }
      bool clear = true;
      for (const Ball& b : keep_out)
        clear = clear && std::hypot(x - b.x, y - b.y, z - b.z) > radius + b.r;
      if (!clear) continue;
      (void)top;
      keep_out.push_back({x, y, z, radius});
      write("object" + std::to_string(k), obj, kind == 0 || kind == 1 || kind == 4);
      break;
    }
  }
  const std::filesystem::path file = folder / "scene.toml";
  std::ofstream(file) << scene.str();
  return file;
}

}  // namespace sb::random_scenes
