//! A report that scales (issue 31, item 4): every ranked variant in one sortable, filterable
//! table (plain JavaScript in the page), the equivalent group summarised, the per-variant
//! tables limited to the recommended and best-ranked variants above 60 ranked, and the Dmax 3
//! palletizer page under 1 MB.

mod common;

use std::path::Path;
use std::process::Command;

use common::{assert_success, counterpoise, run_reduced_palletizer};

/// Rows of the table with id `id`.
fn table_rows(html: &str, id: &str) -> usize {
    let start = html.find(&format!("<table id=\"{id}\"")).unwrap();
    let end = start + html[start..].find("</table>").unwrap();
    html[start..end].matches("<tr").count() - 1
}

#[test]
fn ranking_table_is_complete_sortable_and_filterable() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_reduced_palletizer(dir.path());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    // Every ranked variant (one CSV line each, after the header) is a row of the table.
    assert_eq!(table_rows(&html, "ranking"), csv.lines().count() - 1);
    assert!(html.contains("<select data-f=\"class\">"));
    assert!(html.contains("data-f=\"elements\""));
    assert!(html.contains("data-f=\"dqtr\""));
    assert!(html.contains("<script>//<![CDATA["));
    assert!(!html.contains("<script src"));
}

/// Writes the reports of a stored results.json into a scratch copy (the original untouched).
fn regenerate_copy(dir: &Path) -> (tempfile::TempDir, String) {
    let scratch = tempfile::tempdir().unwrap();
    std::fs::copy(
        dir.join("results.json"),
        scratch.path().join("results.json"),
    )
    .unwrap();
    assert_success(&counterpoise(&["report", scratch.path().to_str().unwrap()]));
    let html = std::fs::read_to_string(scratch.path().join("report.html")).unwrap();
    (scratch, html)
}

fn stored_dir() -> std::path::PathBuf {
    let path = std::env::var("COUNTERPOISE_RANKING_RESULTS").unwrap();
    let path = Path::new(&path);
    if path.is_dir() {
        path.to_path_buf()
    } else {
        path.parent().unwrap().to_path_buf()
    }
}

#[test]
#[ignore = "reads the results.json named by COUNTERPOISE_RANKING_RESULTS (e.g. a Dmax 3 run)"]
fn stored_results_report_is_under_a_megabyte() {
    let dir = stored_dir();
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let ranked = doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["rank"].is_u64())
        .count();
    let (_scratch, html) = regenerate_copy(&dir);
    println!("{ranked} ranked variants, report.html {} bytes", html.len());
    assert!(html.len() < 1_000_000, "{} bytes", html.len());
    assert_eq!(table_rows(&html, "ranking"), ranked);
}

/// Filters and sorts the ranking table in headless Chromium: springs only, elements including
/// K43, sorted by peak spring force; the rows left are checked against ranking.csv.
#[test]
#[ignore = "needs Debian's chromium"]
fn ranking_table_filters_and_sorts_in_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_reduced_palletizer(dir.path());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let probe = r#"<script>//<![CDATA[
window.addEventListener('load', function () {
  var box = document.getElementById('ranking-filter');
  var c = box.querySelector('[data-f="class"]'); c.value = 'springs'; c.dispatchEvent(new Event('input'));
  var e = box.querySelector('[data-f="elements"]'); e.value = 'K43'; e.dispatchEvent(new Event('input'));
  var head = document.getElementById('ranking').tHead.rows[0].cells, k = -1;
  for (var i = 0; i < head.length; i++) if (head[i].textContent.indexOf('Peak spring force') === 0) { k = i; head[i].click(); }
  var rows = [].filter.call(document.getElementById('ranking').tBodies[0].rows, function (r) { return r.style.display !== 'none'; });
  document.title = 'RESULT|' + rows.map(function (r) { return r.cells[1].textContent + '=' + r.cells[k].textContent; }).join('|');
});
//]]></script></body>"#;
    let page = dir.path().join("probe.html");
    std::fs::write(&page, html.replace("</body>", probe)).unwrap();
    let o = Command::new("chromium")
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--dump-dom"])
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&o.stdout);
    let title = dom
        .split("<title>RESULT|")
        .nth(1)
        .unwrap()
        .split("</title>")
        .next()
        .unwrap();
    let got: Vec<(String, f64)> = title
        .split('|')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let (name, force) = s.split_once('=').unwrap();
            (name.to_string(), force.parse().unwrap())
        })
        .collect();
    // The same selection from ranking.csv, sorted by its full-precision force.
    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let mut expected: Vec<(String, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| {
            f[col("class")] == "springs" && f[col("elements")].split(" + ").any(|e| e == "K43")
        })
        .map(|f| {
            (
                f[col("name")].to_string(),
                f[col("peak_spring_force_n")].parse().unwrap(),
            )
        })
        .collect();
    expected.sort_by(|a, b| a.1.total_cmp(&b.1));
    assert!(!expected.is_empty());
    assert_eq!(got.len(), expected.len(), "{title}");
    for ((gn, gf), (en, ef)) in got.iter().zip(&expected) {
        assert!(
            (gf - ef).abs() <= 0.5 + 1e-3 * ef.abs(),
            "{gn} {gf} vs {en} {ef}"
        );
    }
    // Sorted ascending by the displayed force.
    assert!(got.windows(2).all(|w| w[0].1 <= w[1].1), "{title}");
}
