#include "core/trajectory_svg.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace {

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

const char* const kColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e",
                               "#9467bd", "#8c564b", "#e377c2", "#17becf"};

}  // namespace

void WriteTrajectorySvg(const std::string& path, const std::string& title,
                        const std::vector<Eigen::Vector3d>& ground_truth,
                        const std::vector<SvgCurve>& estimates) {
  // Plane: the two principal axes of the reference positions.
  const std::vector<Eigen::Vector3d>* reference = &ground_truth;
  if (reference->size() < 2) {
    for (const SvgCurve& curve : estimates) {
      if (curve.positions.size() >= 2) {
        reference = &curve.positions;
        break;
      }
    }
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  if (reference->size() >= 2) {
    for (const Eigen::Vector3d& p : *reference) mean += p;
    mean /= reference->size();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : *reference) cov += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
    axes.col(0) = solver.eigenvectors().col(2);  // largest
    axes.col(1) = solver.eigenvectors().col(1);
  }
  auto project = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(axes.col(0).dot(p - mean), axes.col(1).dot(p - mean));
  };
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  auto extend = [&](const std::vector<Eigen::Vector3d>& points) {
    for (const Eigen::Vector3d& p : points) {
      if (!p.allFinite()) continue;
      const Eigen::Vector2d q = project(p);
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  };
  extend(ground_truth);
  for (const SvgCurve& curve : estimates) extend(curve.positions);
  if (!(lo.x() <= hi.x())) {
    lo.setZero();
    hi.setOnes();
  }
  const double size = 600.0, margin = 40.0, legend = 20.0 * (estimates.size() + 1);
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-6});
  const double scale = (size - 2 * margin) / span;
  auto to_svg = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = project(p);
    return Eigen::Vector2d(margin + (q.x() - lo.x()) * scale,
                           size - margin - (q.y() - lo.y()) * scale);
  };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\""
      << size + legend << "\" viewBox=\"0 0 " << size << " " << size + legend << "\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << margin << "\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">"
      << Escape(title) << "</text>\n";
  auto polyline = [&](const std::vector<Eigen::Vector3d>& points, const std::string& color,
                      double width, bool dashed) {
    svg << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"" << width << "\""
        << (dashed ? " stroke-dasharray=\"6,3\"" : "") << " points=\"";
    for (const Eigen::Vector3d& p : points) {
      if (!p.allFinite()) continue;
      const Eigen::Vector2d q = to_svg(p);
      svg << q.x() << "," << q.y() << " ";
    }
    svg << "\"/>\n";
  };
  if (!ground_truth.empty()) polyline(ground_truth, "black", 2.0, true);
  for (size_t i = 0; i < estimates.size(); ++i) {
    polyline(estimates[i].positions, kColors[i % std::size(kColors)], 1.5, false);
  }
  // Scale bar and legend.
  const double bar = std::pow(10.0, std::floor(std::log10(span / 2)));
  svg << "<line x1=\"" << margin << "\" y1=\"" << size - 15 << "\" x2=\"" << margin + bar * scale
      << "\" y2=\"" << size - 15 << "\" stroke=\"black\" stroke-width=\"2\"/>\n"
      << "<text x=\"" << margin + bar * scale + 5 << "\" y=\"" << size - 11
      << "\" font-family=\"sans-serif\" font-size=\"11\">" << bar << " m</text>\n";
  double y = size + 5;
  auto legend_entry = [&](const std::string& label, const std::string& color, bool dashed) {
    svg << "<line x1=\"" << margin << "\" y1=\"" << y << "\" x2=\"" << margin + 30 << "\" y2=\""
        << y << "\" stroke=\"" << color << "\" stroke-width=\"2\""
        << (dashed ? " stroke-dasharray=\"6,3\"" : "") << "/>\n<text x=\"" << margin + 38
        << "\" y=\"" << y + 4 << "\" font-family=\"sans-serif\" font-size=\"12\">" << Escape(label)
        << "</text>\n";
    y += 20;
  };
  if (!ground_truth.empty()) legend_entry("ground truth", "black", true);
  for (size_t i = 0; i < estimates.size(); ++i) {
    legend_entry(estimates[i].label, kColors[i % std::size(kColors)], false);
  }
  svg << "</svg>\n";
  std::ofstream file(path);
  file << svg.str();
  if (!file) throw std::runtime_error("cannot write " + path);
}

}  // namespace pldvo
