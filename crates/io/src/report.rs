//! Self-contained HTML reports: one file with every picture inlined, readable in any browser without
//! ParaView or the run folder beside it.
//!
//! A report is a list of blocks (headings, text, tables, pictures, preformatted input). The page carries a
//! few lines of script that, once the page has loaded, record on `<body>` how many pictures decoded
//! (`data-images="loaded/total"`) and how many script errors occurred (`data-script-errors`); a test opens
//! reports in headless Chromium and reads both.

use crate::summary::SummaryFile;
use base64::Engine;
use std::io;
use std::path::Path;

/// One element of a report page.
#[derive(Clone, Debug)]
enum Block {
    Heading(String),
    Text(String),
    Items(Vec<String>),
    Warnings(Vec<String>),
    Table { header: Vec<String>, rows: Vec<Vec<String>> },
    Picture { caption: String, mime: &'static str, data: Vec<u8> },
    Gallery(Vec<(String, &'static str, Vec<u8>)>),
    Pre { summary: String, text: String },
}

/// An HTML report being assembled.
#[derive(Clone, Debug)]
pub struct Report {
    title: String,
    blocks: Vec<Block>,
}

/// The MIME type of a picture file, from its extension.
fn picture_mime(path: &Path) -> Option<&'static str> {
    match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "png" => Some("image/png"),
        "svg" => Some("image/svg+xml"),
        "jpg" | "jpeg" => Some("image/jpeg"),
        _ => None,
    }
}

/// True for a file a report can show as a picture.
pub fn is_picture(path: &Path) -> bool {
    picture_mime(path).is_some()
}

impl Report {
    pub fn new(title: &str) -> Self {
        Report { title: title.to_owned(), blocks: Vec::new() }
    }

    pub fn heading(&mut self, text: &str) -> &mut Self {
        self.blocks.push(Block::Heading(text.to_owned()));
        self
    }

    pub fn text(&mut self, text: &str) -> &mut Self {
        self.blocks.push(Block::Text(text.to_owned()));
        self
    }

    pub fn items(&mut self, items: Vec<String>) -> &mut Self {
        if !items.is_empty() {
            self.blocks.push(Block::Items(items));
        }
        self
    }

    /// Warnings, shown highlighted; nothing when there are none.
    pub fn warnings(&mut self, items: Vec<String>) -> &mut Self {
        if !items.is_empty() {
            self.blocks.push(Block::Warnings(items));
        }
        self
    }

    pub fn table(&mut self, header: Vec<String>, rows: Vec<Vec<String>>) -> &mut Self {
        self.blocks.push(Block::Table { header, rows });
        self
    }

    /// Inlines the picture at `path` (PNG, SVG or JPEG).
    pub fn picture(&mut self, caption: &str, path: &Path) -> io::Result<&mut Self> {
        let (mime, data) = read_picture(path)?;
        self.blocks.push(Block::Picture { caption: caption.to_owned(), mime, data });
        Ok(self)
    }

    /// Pictures side by side (captions under each), e.g. one per case of a study.
    pub fn gallery(&mut self, pictures: &[(String, &Path)]) -> io::Result<&mut Self> {
        let mut items = Vec::with_capacity(pictures.len());
        for (caption, path) in pictures {
            let (mime, data) = read_picture(path)?;
            items.push((caption.clone(), mime, data));
        }
        if !items.is_empty() {
            self.blocks.push(Block::Gallery(items));
        }
        Ok(self)
    }

    /// Preformatted text (an input file, a log excerpt) in a fold that opens on click.
    pub fn pre(&mut self, summary: &str, text: &str) -> &mut Self {
        self.blocks.push(Block::Pre { summary: summary.to_owned(), text: text.to_owned() });
        self
    }

    /// The page as one HTML document.
    pub fn to_html(&self) -> String {
        let mut h = String::with_capacity(4096);
        h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        h.push_str(&format!("<title>{}</title>\n<style>{STYLE}</style>\n", esc(&self.title)));
        h.push_str(&format!("<script>{SCRIPT}</script>\n</head>\n<body data-script-errors=\"0\">\n"));
        h.push_str(&format!("<h1>{}</h1>\n", esc(&self.title)));
        for b in &self.blocks {
            match b {
                Block::Heading(t) => h.push_str(&format!("<h2>{}</h2>\n", esc(t))),
                Block::Text(t) => h.push_str(&format!("<p>{}</p>\n", esc(t))),
                Block::Items(v) => {
                    h.push_str("<ul>\n");
                    for i in v {
                        h.push_str(&format!("<li>{}</li>\n", esc(i)));
                    }
                    h.push_str("</ul>\n");
                }
                Block::Warnings(v) => {
                    h.push_str("<div class=\"warn\"><strong>Warnings</strong><ul>\n");
                    for i in v {
                        h.push_str(&format!("<li>{}</li>\n", esc(i)));
                    }
                    h.push_str("</ul></div>\n");
                }
                Block::Table { header, rows } => {
                    h.push_str("<div class=\"scroll\"><table>\n<tr>");
                    for c in header {
                        h.push_str(&format!("<th>{}</th>", esc(c)));
                    }
                    h.push_str("</tr>\n");
                    for r in rows {
                        h.push_str("<tr>");
                        for c in r {
                            h.push_str(&format!("<td>{}</td>", esc(c)));
                        }
                        h.push_str("</tr>\n");
                    }
                    h.push_str("</table></div>\n");
                }
                Block::Picture { caption, mime, data } => {
                    h.push_str(&format!(
                        "<figure><img alt=\"{c}\" src=\"{}\"><figcaption>{c}</figcaption></figure>\n",
                        data_uri(mime, data),
                        c = esc(caption)
                    ));
                }
                Block::Gallery(items) => {
                    h.push_str("<div class=\"gallery\">\n");
                    for (caption, mime, data) in items {
                        h.push_str(&format!(
                            "<figure><img alt=\"{c}\" src=\"{}\"><figcaption>{c}</figcaption></figure>\n",
                            data_uri(mime, data),
                            c = esc(caption)
                        ));
                    }
                    h.push_str("</div>\n");
                }
                Block::Pre { summary, text } => {
                    h.push_str(&format!(
                        "<details><summary>{}</summary><pre>{}</pre></details>\n",
                        esc(summary),
                        esc(text)
                    ));
                }
            }
        }
        h.push_str(&format!("<footer>spatter {}</footer>\n</body>\n</html>\n", env!("CARGO_PKG_VERSION")));
        h
    }

    /// Writes the page to `path` (atomically: temporary file, then rename).
    pub fn write(&self, path: &Path) -> io::Result<()> {
        let tmp = path.with_extension("html.tmp");
        std::fs::write(&tmp, self.to_html())
            .map_err(|e| io::Error::new(e.kind(), format!("cannot write {}: {e}", tmp.display())))?;
        std::fs::rename(&tmp, path)
    }
}

fn read_picture(path: &Path) -> io::Result<(&'static str, Vec<u8>)> {
    let mime = picture_mime(path).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not a PNG, SVG or JPEG picture", path.display()),
        )
    })?;
    let data = std::fs::read(path)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot read picture {}: {e}", path.display())))?;
    Ok((mime, data))
}

fn data_uri(mime: &str, data: &[u8]) -> String {
    format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(data))
}

/// `text` with the characters HTML gives meaning to escaped.
pub fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.6em}h2{font-size:1.25em;margin-top:1.6em;border-bottom:1px solid #ddd}\
table{border-collapse:collapse;font-size:.9em}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right}\
th{background:#f3f3f3}td:first-child,th:first-child{text-align:left}.scroll{overflow-x:auto}\
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #eee}figcaption{font-size:.9em;color:#555}\
.gallery{display:grid;grid-template-columns:repeat(auto-fill,minmax(280px,1fr));gap:.8em}\
.warn{background:#fff4e0;border-left:4px solid #e69f00;padding:.4em 1em}pre{background:#f7f7f7;padding:.8em;overflow-x:auto}\
footer{margin-top:3em;font-size:.8em;color:#888}";

/// Marks `<body>` with the number of decoded pictures and of script errors once the page has loaded.
const SCRIPT: &str = "window.addEventListener('error',function(e){if(e.target===window||!e.target||!e.target.tagName){\
var b=document.body;if(b){b.setAttribute('data-script-errors',String(Number(b.getAttribute('data-script-errors')||0)+1));}}});\
window.addEventListener('load',function(){var im=document.images,ok=0;for(var i=0;i<im.length;i++){\
if(im[i].complete&&im[i].naturalWidth>0){ok++;}}document.body.setAttribute('data-images',ok+'/'+im.length);});";

/// The report of one run folder: its key numbers, pictures, warnings, cost and resolved input, from
/// `summary.json`, `run.toml` and `log.txt`. Written as `report.html` in the folder.
pub fn write_run_report(root: &Path, title: &str) -> io::Result<std::path::PathBuf> {
    let summary = SummaryFile::read(root)
        .map_err(io::Error::other)?
        .ok_or_else(|| io::Error::other(format!("{} holds no summary.json", root.display())))?;
    let mut r = Report::new(title);
    r.text(&format!(
        "Scenario kind `{}`, {}, {:.1} s of wall time on {} thread{}.",
        summary.kind,
        if summary.completed() { "completed" } else { "stopped early (resume to finish)" },
        summary.wall_time_s,
        summary.threads,
        if summary.threads == 1 { "" } else { "s" }
    ));
    let warnings: Vec<String> = summary
        .headline
        .iter()
        .filter_map(|l| l.strip_prefix("warning: ").map(str::to_owned))
        .chain(log_warnings(&root.join("log.txt")))
        .collect();
    r.warnings(dedup(warnings));
    if !summary.scalars.is_empty() {
        r.heading("Key numbers");
        r.table(
            vec!["quantity".into(), "value".into()],
            summary
                .scalars
                .iter()
                .map(|(k, v)| vec![k.clone(), v.map(crate::fmt_f64).unwrap_or_else(|| "not finite".into())])
                .collect(),
        );
    }
    r.heading("Summary");
    r.items(summary.headline.iter().filter(|l| !l.starts_with("warning: ")).cloned().collect());
    let pictures: Vec<(String, std::path::PathBuf)> = summary
        .artifacts
        .iter()
        .map(|(l, p)| (l.clone(), if p.is_absolute() { p.clone() } else { root.join(p) }))
        .filter(|(_, p)| p.extension().is_some_and(|e| e == "png") && p.is_file())
        .collect();
    if !pictures.is_empty() {
        r.heading("Pictures");
        for (label, p) in &pictures {
            r.picture(label, p)?;
        }
    }
    let files: Vec<String> = summary
        .artifacts
        .iter()
        .filter(|(_, p)| p.extension().is_none_or(|e| e != "png"))
        .map(|(l, p)| format!("{l}: {}", p.display()))
        .collect();
    if !files.is_empty() {
        r.heading("Files");
        r.items(files);
    }
    if let Ok(input) = std::fs::read_to_string(root.join("run.toml")) {
        r.heading("Input");
        r.pre("the fully resolved input (run.toml)", &input);
    }
    let path = root.join("report.html");
    r.write(&path)?;
    Ok(path)
}

/// Warning lines of a run log (the message after the level).
fn log_warnings(log: &Path) -> Vec<String> {
    let Ok(text) = std::fs::read_to_string(log) else { return Vec::new() };
    text.lines().filter_map(|l| l.split_once(" WARN ").map(|(_, m)| m.trim().to_owned())).collect()
}

fn dedup(v: Vec<String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(v.len());
    for s in v {
        if !out.contains(&s) {
            out.push(s);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::RunSummary;
    use spatter_core::control::Finished;

    #[test]
    fn text_is_escaped_and_pictures_are_inlined() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("a.png");
        crate::plot::Chart::new("t", "x", "y").line("l", &[(0.0, 0.0), (1.0, 1.0)]).save_png(&png).unwrap();
        let mut r = Report::new("A <b> & c");
        r.text("x < y").picture("curve", &png).unwrap();
        let html = r.to_html();
        assert!(html.contains("<title>A &lt;b&gt; &amp; c</title>") && html.contains("x &lt; y"));
        assert!(html.contains("src=\"data:image/png;base64,iVBOR"), "PNG inlined");
        assert!(r.picture("x", &dir.path().join("a.txt")).is_err());
    }

    #[test]
    fn a_run_report_shows_numbers_warnings_pictures_and_input() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        let png = root.join("map.png");
        crate::plot::Chart::new("t", "x", "y").line("l", &[(0.0, 0.0), (1.0, 2.0)]).save_png(&png).unwrap();
        let mut s = RunSummary::new(Finished::Completed);
        s.scalar("stick_fraction", 0.25);
        s.headline.push("warning: few particles".into());
        s.headline.push("42 impacts".into());
        s.artifacts.push(("regime map".into(), png));
        SummaryFile::of(&s, "snow_regime_map", root, 2.0, 2).write(root).unwrap();
        std::fs::write(root.join("run.toml"), "kind = \"snow_regime_map\"\n").unwrap();
        std::fs::write(root.join("log.txt"), "2026-01-01T00:00:00Z  WARN dt is large\n").unwrap();
        let path = write_run_report(root, "snow run").unwrap();
        let html = std::fs::read_to_string(path).unwrap();
        for needle in [
            "stick_fraction",
            "0.25",
            "few particles",
            "dt is large",
            "42 impacts",
            "data:image/png",
            "kind = &quot;snow_regime_map&quot;",
        ] {
            assert!(html.contains(needle), "{needle} missing");
        }
    }
}
