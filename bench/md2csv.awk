# Writes every markdown table of the input as a CSV file, for plots and other
# tools: DIR/PREFIX_TITLE.csv, TITLE from the line introducing the table (a
# short line ending in ':'), else from the last heading (up to its first ':'
# or '('), lowercased, non-alphanumerics as '-'. A second table with the same
# title gets a suffix -2, -3, ... Cells lose markdown emphasis, backticks and
# a trailing unit (MiB, %); cells with commas or quotes are quoted.
#   awk -v dir=DIR -v prefix=PREFIX -f bench/md2csv.awk FILE.md
function slug(s) {
    sub(/^#+ */, "", s)
    sub(/[:(].*$/, "", s)
    s = tolower(s)
    gsub(/[^a-z0-9]+/, "-", s)
    gsub(/^-+|-+$/, "", s)
    return substr(s, 1, 40)
}
function cell(s) {
    gsub(/\*\*|`/, "", s)
    gsub(/^ +| +$/, "", s)
    if (s ~ /^-?[0-9.]+ MiB$/) sub(/ MiB$/, "", s)
    if (s ~ /^-?[0-9.]+%$/) sub(/%$/, "", s)
    if (s ~ /[,"]/) { gsub(/"/, "\"\"", s); s = "\"" s "\"" }
    return s
}
/^#/ { heading = slug($0); intro = ""; next }
/^\|/ {
    if (!out) {
        t = intro != "" ? intro : heading
        n = ++seen[t]
        out = dir "/" prefix "_" t (n > 1 ? "-" n : "") ".csv"
        printf "" > out
    }
    if ($0 ~ /^\|[-:| ]+\|$/) next
    line = $0
    sub(/^\| */, "", line)
    sub(/ *\|$/, "", line)
    k = split(line, f, / *\| */)
    row = ""
    for (i = 1; i <= k; i++) row = row (i > 1 ? "," : "") cell(f[i])
    print row > out
    next
}
{
    if (out) { close(out); out = ""; intro = "" }
    if ($0 ~ /:$/ && length($0) < 240) intro = slug($0)
    else if ($0 != "") intro = ""
}
END { if (out) close(out) }
