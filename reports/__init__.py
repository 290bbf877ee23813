"""Reports: HTML, Markdown and JSON documents and their figures, made from campaign output.

- :mod:`reports.load`            read a campaign's output folder
- :mod:`reports.figures`         the matplotlib figures (seed Figs. 1, 3-7 and more)
- :mod:`reports.render`          the format-free document model
- :mod:`reports.render_tables`, :mod:`reports.render_values`  tables as shown; numbers and provenance as text
- :mod:`reports.html`, :mod:`reports.markdown`, :mod:`reports.jsonreport`  the three formats
- :mod:`reports.campaign_report` any campaign's report (``sidbench report DIR``)
- :mod:`reports.findings`        what the scores show, ranked: biases, coverage failures, comparison
- :mod:`reports.lead`, :mod:`reports.campaign_setup`  the report's lead lines and set-up section
- :mod:`reports.nightly_report`  the nightly accuracy report with gates and trends
- :mod:`reports.benchmark_report` methods ranked by accuracy, honesty and cost
- :mod:`reports.maneuver_review` the maneuver design review
- :mod:`reports.browser`, :mod:`reports.screenshot`  headless Chromium checks and screenshots
"""
