// The seed list of Region-Growing Marching Cubes in the properties panel, with a handle in the
// render view that places seeds (P: on the surface under the mouse, Ctrl+P: nearest point).
#include "pqRGSeedPointsPropertyWidget.h"
#include "ui_pqRGSeedPointsPropertyWidget.h"

#include "pqApplicationCore.h"
#include "pqCoreUtilities.h"
#include "pqDoubleLineEdit.h"
#include "pqLiveInsituVisualizationManager.h"
#include "pqPointPickingHelper.h"
#include "pqServer.h"
#include "pqServerManagerModel.h"
#include "pqUndoStack.h"
#include "pqView.h"

#include "vtkBoundingBox.h"
#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkSMNewWidgetRepresentationProxy.h"
#include "vtkSMParaViewPipelineController.h"
#include "vtkSMPropertyGroup.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMSessionProxyManager.h"

#include <QCheckBox>
#include <QHeaderView>
#include <QPushButton>
#include <QTableWidget>

#include <algorithm>
#include <set>

//-----------------------------------------------------------------------------
pqRGSeedPointsPropertyWidget::pqRGSeedPointsPropertyWidget(
  vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent)
  : Superclass("representations", "HandleWidgetRepresentation", proxy, group, parent)
  , Form(new Ui::RGSeedPointsWidget())
{
  this->setObjectName("RGSeedPoints");
  this->setShowLabel(false);
  this->createHandle(proxy);
  this->setupUserObserver(proxy);

  // The form (pqRGSeedPointsPropertyWidget.ui), then what depends on the font.
  this->Form->setupUi(this);
  this->Table = this->Form->SeedTable;
  this->Position[0] = this->Form->HandleX;
  this->Position[1] = this->Form->HandleY;
  this->Position[2] = this->Form->HandleZ;
  this->Table->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  this->Table->verticalHeader()->setDefaultSectionSize(this->fontMetrics().height() + 6);
  this->Table->setMinimumHeight(4 * (this->fontMetrics().height() + 6));
  this->connectControls();
  this->setWidgetVisible(this->Form->ShowHandle->isChecked());

  // P puts the handle on the surface under the mouse, Ctrl+P on the nearest mesh point.
  for (bool onMesh : { false, true })
  {
    auto* picker = new pqPointPickingHelper(
      onMesh ? QKeySequence(tr("Ctrl+P")) : QKeySequence(tr("P")), onMesh, this);
    QObject::connect(this, &pqPropertyWidget::viewChanged, picker, &pqPointPickingHelper::setView);
    QObject::connect(
      picker, &pqPointPickingHelper::pick, this, &pqRGSeedPointsPropertyWidget::setHandlePosition);
  }

  if (vtkSMProperty* seeds = group->GetProperty("SeedPoints"))
  {
    this->addPropertyLink(this, "seedPoints", SIGNAL(seedPointsChanged()), seeds);
  }
  else
  {
    qCritical("The seed points widget needs a property for the function 'SeedPoints'.");
  }
  this->showHandlePosition();
}

//-----------------------------------------------------------------------------
// The handle is a widget proxy of its own, on the session that renders (for Catalyst, the
// display session). It is not linked to any property of the filter: it only points.
void pqRGSeedPointsPropertyWidget::createHandle(vtkSMProxy* proxy)
{
  {
    pqScopedUndoExclude noUndo;
    pqServer* server =
      pqApplicationCore::instance()->getServerManagerModel()->findServer(proxy->GetSession());
    server = pqLiveInsituVisualizationManager::displaySession(server);
    vtkSmartPointer<vtkSMProxy> created;
    created.TakeReference(
      server->proxyManager()->NewProxy("representations", "HandleWidgetRepresentation"));
    this->Handle = vtkSMNewWidgetRepresentationProxy::SafeDownCast(created);
    if (!this->Handle)
    {
      // ParaView defines this proxy; without it no interactive widget can work.
      qFatal("ParaView has no HandleWidgetRepresentation proxy for the seed handle.");
    }
    vtkNew<vtkSMParaViewPipelineController> controller;
    controller->InitializeProxy(this->Handle);
    this->Handle->UpdateVTKObjects();
    // A prototype is ignored by undo/redo and state files.
    this->Handle->PrototypeOn();
  }
  pqCoreUtilities::connect(
    this->Handle, vtkCommand::InteractionEvent, this, SLOT(handleMoved()), Qt::QueuedConnection);
  pqCoreUtilities::connect(
    this->Handle, vtkCommand::EndInteractionEvent, this, SLOT(handleMoved()), Qt::QueuedConnection);
}

//-----------------------------------------------------------------------------
// The form's controls to what they do: the seed table and its buttons, the handle's position
// fields, its visibility, and centring it.
void pqRGSeedPointsPropertyWidget::connectControls()
{
  using Self = pqRGSeedPointsPropertyWidget;
  QObject::connect(
    this->Table, &QTableWidget::itemChanged, this, [this]() { this->tableEdited(); });
  QObject::connect(this->Table, &QTableWidget::itemSelectionChanged, this, &Self::seedSelected);
  QObject::connect(this->Form->AddSeed, &QPushButton::clicked, this, &Self::addSeedAtHandle);
  QObject::connect(
    this->Form->RemoveSeeds, &QPushButton::clicked, this, &Self::removeSelectedSeeds);
  QObject::connect(this->Form->RemoveAllSeeds, &QPushButton::clicked, this, &Self::removeAllSeeds);
  for (int axis = 0; axis < 3; ++axis)
  {
    QObject::connect(this->Position[axis], &pqDoubleLineEdit::textChangedAndEditingFinished, this,
      &Self::handlePositionTyped);
  }
  QCheckBox* show = this->Form->ShowHandle;
  QObject::connect(show, &QCheckBox::toggled, this, &Self::setWidgetVisible);
  QObject::connect(this, &Self::widgetVisibilityToggled, show, &QCheckBox::setChecked);
  QObject::connect(this->Form->CenterOnBounds, &QPushButton::clicked, this, &Self::centerOnBounds);
}

//-----------------------------------------------------------------------------
pqRGSeedPointsPropertyWidget::~pqRGSeedPointsPropertyWidget()
{
  // Take the handle out of the view it was shown in.
  if (pqView* view = this->view())
  {
    vtkSMPropertyHelper(view->getProxy(), "HiddenRepresentations", true).Remove(this->Handle);
    view->getProxy()->UpdateVTKObjects();
  }
}

//-----------------------------------------------------------------------------
vtkSMNewWidgetRepresentationProxyAbstract* pqRGSeedPointsPropertyWidget::internalWidgetProxy()
{
  return this->Handle;
}

//-----------------------------------------------------------------------------
QList<QVariant> pqRGSeedPointsPropertyWidget::seedPoints() const
{
  QList<QVariant> values;
  for (int row = 0; row < this->Table->rowCount(); ++row)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      const QTableWidgetItem* item = this->Table->item(row, axis);
      bool ok = false;
      const double value = item ? item->text().toDouble(&ok) : 0.0;
      values.push_back(ok ? value : 0.0);
    }
  }
  return values;
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::setSeedPoints(const QList<QVariant>& values)
{
  const bool updating = this->Updating;
  this->Updating = true;
  const int rows = static_cast<int>(values.size() / 3);
  this->Table->setRowCount(rows);
  for (int row = 0; row < rows; ++row)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      const QString text = pqCoreUtilities::number(values[3 * row + axis].toDouble());
      if (QTableWidgetItem* item = this->Table->item(row, axis))
      {
        item->setText(text);
      }
      else
      {
        this->Table->setItem(row, axis, new QTableWidgetItem(text));
      }
    }
  }
  this->Updating = updating;
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::handlePosition(double position[3]) const
{
  vtkSMPropertyHelper(this->Handle, "WorldPosition").Get(position, 3);
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::addSeedAtHandle()
{
  double position[3];
  this->handlePosition(position);
  QList<QVariant> values = this->seedPoints();
  values << position[0] << position[1] << position[2];
  this->setSeedPoints(values);
  this->Table->selectRow(this->Table->rowCount() - 1);
  Q_EMIT this->seedPointsChanged();
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::removeSelectedSeeds()
{
  std::set<int> rows;
  for (const QModelIndex& index : this->Table->selectionModel()->selectedRows())
  {
    rows.insert(index.row());
  }
  if (rows.empty())
  {
    return;
  }
  const QList<QVariant> values = this->seedPoints();
  QList<QVariant> kept;
  for (int i = 0; i < values.size(); ++i)
  {
    if (rows.count(i / 3) == 0)
    {
      kept.push_back(values[i]);
    }
  }
  this->setSeedPoints(kept);
  Q_EMIT this->seedPointsChanged();
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::removeAllSeeds()
{
  if (this->Table->rowCount() > 0)
  {
    this->setSeedPoints({});
    Q_EMIT this->seedPointsChanged();
  }
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::centerOnBounds()
{
  vtkBoundingBox bounds = this->inputBounds();
  if (bounds.IsValid())
  {
    double center[3];
    bounds.GetCenter(center);
    this->setHandlePosition(center[0], center[1], center[2]);
  }
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::setHandlePosition(double x, double y, double z)
{
  const double position[3] = { x, y, z };
  vtkSMPropertyHelper(this->Handle, "WorldPosition").Set(position, 3);
  this->Handle->UpdateVTKObjects();
  this->Placed = true;
  this->showHandlePosition();
  this->render();
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::placeWidget()
{
  // The first time the panel shows the widget, put the handle where the last seed is, or in
  // the middle of the data; afterwards leave it where the user put it.
  if (this->Placed)
  {
    return;
  }
  const QList<QVariant> values = this->seedPoints();
  if (values.size() >= 3)
  {
    const int last = static_cast<int>(values.size()) - 3;
    this->setHandlePosition(
      values[last].toDouble(), values[last + 1].toDouble(), values[last + 2].toDouble());
  }
  else if (this->inputBounds().IsValid())
  {
    this->centerOnBounds();
  }
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::handlePositionTyped()
{
  double position[3];
  this->handlePosition(position);
  for (int axis = 0; axis < 3; ++axis)
  {
    bool ok = false;
    const double value = this->Position[axis]->text().toDouble(&ok);
    if (ok)
    {
      position[axis] = value;
    }
  }
  this->setHandlePosition(position[0], position[1], position[2]);
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::handleMoved()
{
  // The representation's position after a drag is in its information property; the proxy's
  // WorldPosition follows it through the proxy's own links.
  this->Handle->UpdatePropertyInformation();
  double position[3];
  vtkSMPropertyHelper(this->Handle, "WorldPositionInfo").Get(position, 3);
  vtkSMPropertyHelper(this->Handle, "WorldPosition").Set(position, 3);
  this->Placed = true;
  this->showHandlePosition();
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::tableEdited()
{
  if (!this->Updating)
  {
    Q_EMIT this->seedPointsChanged();
  }
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::seedSelected()
{
  const QModelIndexList rows = this->Table->selectionModel()->selectedRows();
  if (this->Updating || rows.size() != 1)
  {
    return;
  }
  const QList<QVariant> values = this->seedPoints();
  const int row = rows.front().row();
  this->setHandlePosition(
    values[3 * row].toDouble(), values[3 * row + 1].toDouble(), values[3 * row + 2].toDouble());
}

//-----------------------------------------------------------------------------
vtkBoundingBox pqRGSeedPointsPropertyWidget::inputBounds()
{
  // The filter's current input (Change Input may have replaced it since the panel was made).
  if (vtkSMProperty* input = this->proxy()->GetProperty("Input"))
  {
    this->setDataSource(vtkSMPropertyHelper(input).GetAsProxy());
  }
  return this->dataBounds();
}

//-----------------------------------------------------------------------------
void pqRGSeedPointsPropertyWidget::showHandlePosition()
{
  double position[3];
  this->handlePosition(position);
  for (int axis = 0; axis < 3; ++axis)
  {
    this->Position[axis]->setTextAndResetCursor(pqCoreUtilities::number(position[axis]));
  }
}
