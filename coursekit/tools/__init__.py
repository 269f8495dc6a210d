"""The course's tools, beside its algorithms: for instructors and maintainers, not for students.

* `notebooks` finds, reads, writes and executes the chapter notebooks and gives their figures
  their text alternatives, for every tool below; `chapters` gives the tools and the tests the
  course's one registry of chapters, explorers and exercises (`coursekit._chapters`); `cells`
  names the roles of a notebook's cells that the other tools read; `builds` holds what the
  builds share;
* `release` writes the student edition, `slides` the slide metadata, `colab` the install cell;
* `site` builds the course website (`site_figures` draws its figures for the page,
  `static_explorers` renders the explorers' frames for pages without a kernel), `slideshow`
  the slides of every chapter, `grading` (a package: grader, runner, kernel, sandbox) grades
  submitted notebooks, each sealed off.

``python -m coursekit --help`` lists the commands that call them.
"""
