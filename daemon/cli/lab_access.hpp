#pragma once
// The lab database for `hystlab lab ...` and `hystlab runs export --pg`: the connection (--pg URL,
// its password from --pg-password-file or libpq's own $PGPASSWORD and ~/.pgpass, never the
// command line), a daemon by name, and the lab's failures as one CliError line each.
#include <cstdint>
#include <memory>
#include <string>

#include "cli_support.hpp"
#include "hystlab/db/lab_reads.hpp"
#include "hystlab/db/pg.hpp"

namespace hystlab::cli {

// What the lab's commands take besides their own options.
inline const char* kLabConnectionHelp = R"(--pg URL names the lab database (postgresql://USER@HOST[:PORT]/DB, or key=value pairs), as the
daemons' lab.postgresql does; $HYSTLAB_PG when --pg is not given. Its password is never on the
command line (others see it in ps): --pg-password-file FILE (its first line), or libpq's own
$PGPASSWORD or ~/.pgpass. A URL that holds a password is refused.
)";

// Connected to --pg (or $HYSTLAB_PG): the session's times in UTC, the lab's schema there.
// CliError for a URL with a password, an unreadable password file, no server, a refused
// password, a database no daemon replicates to.
[[nodiscard]] std::unique_ptr<db::PgConnection> connect_lab(const Options& opt);

// The id of the daemon called `name` (in lab `lab` when not empty): a CliError names the
// daemons there are when none is, and asks for --lab when two labs have one of that name.
[[nodiscard]] db::LabDaemon lab_daemon(db::LabReads& lab, const std::string& name, const std::string& lab_name);

// A lab timestamp (timestamptz as text in UTC, "2026-11-28 01:00:03.25+00") in the daemons' own
// form ("2026-11-28T01:00:03.25Z"): utc_time() and the event lines read it as they read a file's.
[[nodiscard]] std::string iso_of_lab_time(const std::string& pg_text);

// A PgError of a query as one line (libpq's messages can span several).
[[nodiscard]] std::string one_line(const std::string& text);

}  // namespace hystlab::cli
