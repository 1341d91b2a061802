#include "lab_access.hpp"

#include <cstdlib>
#include <fstream>

namespace hystlab::cli {

std::string one_line(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n' || c == '\r' || c == '\t') {
      if (!out.empty() && out.back() != ' ') out.push_back(' ');
    } else {
      out.push_back(c);
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

namespace {
// The first line of --pg-password-file (trailing blanks and \r dropped): never empty.
std::string password_from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw CliError("--pg-password-file: cannot read '" + path + "'");
  std::string line;
  std::getline(in, line);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  if (line.empty()) throw CliError("--pg-password-file: the first line of '" + path + "' is empty");
  return line;
}
}  // namespace

std::unique_ptr<db::PgConnection> connect_lab(const Options& opt) {
  std::string url = opt.get("pg");
  if (url.empty()) {
    const char* env = std::getenv("HYSTLAB_PG");
    url = env != nullptr ? env : "";
  }
  if (url.empty()) throw CliError("missing required option --pg (the lab database, postgresql://USER@HOST/DB; or $HYSTLAB_PG)");
  if (db::conninfo_has_password(url))
    throw CliError("--pg holds a password: give it in --pg-password-file FILE, $PGPASSWORD or ~/.pgpass, never on the command line");
  const std::string password = opt.has("pg-password-file") ? password_from_file(opt.get("pg-password-file")) : std::string();
  std::unique_ptr<db::PgConnection> pg;
  try {
    pg = std::make_unique<db::PgConnection>(url, password);
  } catch (const db::PgError& e) {
    std::string why = one_line(e.what());
    if (const std::string prefix = "PostgreSQL: cannot connect: "; why.starts_with(prefix)) why.erase(0, prefix.size());
    if (e.sqlstate == "28P01")
      throw CliError("--pg: the lab database refused the password (" + why + "; the password comes from " +
                     (password.empty() ? std::string("$PGPASSWORD or ~/.pgpass") : "--pg-password-file") + ")");
    throw CliError("--pg: cannot connect to the lab database " + url + ": " + why);
  }
  try {
    pg->exec("SET TimeZone = 'UTC'");
    if (pg->query("SELECT to_regclass('hystlab.lab_campaigns') IS NULL").text(0, 0) == "t")
      throw CliError("--pg: " + url + " holds no lab (no hystlab schema: no daemon replicates to this database)");
  } catch (const db::PgError& e) {
    throw CliError("--pg: " + one_line(e.what()));
  }
  return pg;
}

db::LabDaemon lab_daemon(db::LabReads& lab, const std::string& name, const std::string& lab_name) {
  std::vector<db::LabDaemon> found;
  std::string known;
  for (db::LabDaemon& d : lab.daemons(lab_name)) {
    known += (known.empty() ? "" : ", ") + d.name;
    if (d.name == name) found.push_back(std::move(d));
  }
  const std::string where = lab_name.empty() ? "the lab database" : "lab '" + lab_name + "'";
  if (found.empty()) throw CliError("no daemon '" + name + "' in " + where + " (" + (known.empty() ? "it has none" : "it has " + known) + ")");
  if (found.size() > 1) throw CliError("daemon '" + name + "' is in labs '" + found[0].lab + "' and '" + found[1].lab + "': give --lab NAME");
  return found.front();
}

std::string iso_of_lab_time(const std::string& t) {
  if (t.size() < 22 || t[10] != ' ' || !t.ends_with("+00")) return t;
  return t.substr(0, 10) + "T" + t.substr(11, t.size() - 14) + "Z";
}

}  // namespace hystlab::cli
